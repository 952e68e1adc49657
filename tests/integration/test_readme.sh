#!/bin/sh
# test_readme.sh — README.md is true when typed: its sh and console blocks run
# in order, as a new user types them after `make run` (build/packd in the
# checkout, the daemon on 127.0.0.1), here against a real daemon on a free
# loopback port with a temporary data directory and a scratch working
# directory; the outputs the README marks as real are compared.  The rules
# (markers, wildcards, what is normalised) are in readme_blocks.py.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
README=${READMETEST_FILE:-$SRC/README.md}

start_daemon readme || { fail readme_daemon_starts; exit 1; }
PORT=${B##*:}
W="$T/work" # what the checkout offers the commands: examples/, tests/, build/packd
mkdir -p "$W"
ln -s "$SRC/examples" "$W/examples"
ln -s "$SRC/tests" "$W/tests"
ln -s "$(cd "$(dirname "$PACKD")" && pwd)" "$W/build"
PACKD_SERVER=$B LC_ALL=C.UTF-8 SHELL=/bin/sh READMETEST_SLOW=$SLOW \
    python3 "$SRC/tests/integration/readme_blocks.py" "$README" "$W" "$PORT"
exit 0
