#!/bin/sh
# test_examples_digest.sh — every example job computes the same numbers as
# recorded in tests/data/example-digests.txt: one SHA-256 per dataset of each
# result (tests/tools/h5digest.sh; wall-clock figures left out).  A change
# meant to keep behaviour (a refactoring) keeps every line; a change meant to
# alter results regenerates the file with PACKD_DIGEST_UPDATE=1 and says why.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$PWD}
REF="$SRC/tests/data/example-digests.txt"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "$SRC/tests/integration/check.inc"

# run NAME JOB — from the source tree (the examples name their mesh files
# relative to it) or from $T (the homogenize examples read rve-2d.h5 there).
out="$T/digests.txt"
: >"$out"
run() {
    name=$1
    if (cd "$2" && "$PACKD" run "$3" -o "$T/$name.h5" >"$T/$name.json" 2>"$T/$name.err"); then
        sh "$SRC/tests/tools/h5digest.sh" "$T/$name.h5" | sed "s|^|$name |" >>"$out"
    else
        fail "example $name runs" "$(head -c 300 "$T/$name.err")"
    fi
}
for j in "$SRC"/examples/*.json; do
    run "$(basename "$j" .json)" "$SRC" "$j"
done
run rve-2d "$T" "$SRC/examples/homogenize/rve-rsa-2d.json"
for j in "$SRC"/examples/homogenize/homogenize-*.json; do
    run "$(basename "$j" .json)" "$T" "$j"
done

if [ "${PACKD_DIGEST_UPDATE:-0}" = 1 ]; then
    cp "$out" "$REF"
    echo "PASS digests written to $REF ($(wc -l <"$out") datasets)"
    exit 0
fi
n=$(wc -l <"$REF")
if diff "$REF" "$out" >"$T/diff"; then
    pass "every example's $n datasets have their recorded digests"
else
    fail "example results differ from tests/data/example-digests.txt" "$(head -20 "$T/diff")"
fi
