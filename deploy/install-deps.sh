#!/bin/sh
# install-deps.sh — install the Debian packages packd needs, only when missing.
# Safe to run repeatedly (it only checks when nothing is missing); `make` runs it once per
# build directory.
set -eu
if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: not a Debian system; install the equivalents of these by hand:" >&2
    echo "  libmicrohttpd jansson sqlite3 hdf5 (+ h5dump) suitesparse/cholmod openblas (serial) curl python3-jsonschema" >&2
    exit 0
fi
PKGS="build-essential pkg-config libmicrohttpd-dev libcurl4-openssl-dev libssl-dev libjansson-dev libsqlite3-dev libhdf5-dev hdf5-tools curl python3 python3-jsonschema libsuitesparse-dev libopenblas0-serial procps"
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "install-deps: installing:$missing"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing
