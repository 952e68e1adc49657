#!/bin/sh
# install-deps.sh — install the Debian packages packd needs, only when missing.
# Safe to run repeatedly (it only checks when nothing is missing); `make` runs it once per
# build directory.  As root it runs apt-get itself, as another user through sudo when
# sudo is installed; otherwise it prints the one command to run as root and fails.
set -eu
PKGS="build-essential pkg-config libmicrohttpd-dev libcurl4-openssl-dev libssl-dev libjansson-dev libsqlite3-dev libhdf5-dev hdf5-tools curl python3 python3-jsonschema python3-matplotlib python3-owslib libsuitesparse-dev libopenblas0-serial procps libcairo2-dev fonts-dejavu-core clang libclang-rt-14-dev chromium nodejs"
if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: not a Debian system; install the equivalents of these by hand:" >&2
    echo "  $PKGS" >&2
    exit 0
fi
# The dashboard's browser test (tests/integration/test_dashboard.sh) drives
# chromium with playwright-core from npm; a node from elsewhere (NodeSource)
# brings its own npm, which Debian's npm package would conflict with.
command -v npm >/dev/null 2>&1 || PKGS="$PKGS npm"
# Optional: what bench/service.sh drives the daemon with (PACKD_BENCH_DEPS=1).
[ "${PACKD_BENCH_DEPS:-0}" = 1 ] && PKGS="$PKGS wrk sqlite3"
# Tests: the one-node Slurm of tests/integration/test_slurm.sh and bench/scale.sh (they
# call this with PACKD_TEST_DEPS=1 and skip, naming why, when it cannot install).
[ "${PACKD_TEST_DEPS:-0}" = 1 ] && PKGS="$PKGS slurm-wlm munge"
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "install-deps: missing Debian packages:$missing"
if [ "$(id -u)" -eq 0 ]; then
    AS=""
elif command -v sudo >/dev/null 2>&1; then
    AS="sudo"
else
    echo "install-deps: not root and no sudo here; as root, run:" >&2
    echo "  su -c 'apt-get update && apt-get install -y --no-install-recommends$missing'" >&2
    echo "then run make again." >&2
    exit 1
fi
# env: sudo resets the environment
$AS env DEBIAN_FRONTEND=noninteractive apt-get update -qq
# shellcheck disable=SC2086
$AS env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
