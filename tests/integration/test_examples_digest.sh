#!/bin/sh
# test_examples_digest.sh — every example job computes the same numbers as
# recorded in tests/data/example-digests.txt: one SHA-256 per dataset of each
# result (tests/tools/h5digest.sh; wall-clock figures left out).  A change
# meant to keep behaviour (a refactoring) keeps every line; a change meant to
# alter results regenerates the file with PACKD_DIGEST_UPDATE=1 and says why.
# The numbers may not depend on the machine: the examples run with
# OPENBLAS_CORETYPE unset (OpenBLAS picks its kernel for this CPU), then again
# with another kernel and the other OpenBLAS flavour (serial/pthread, where
# both are installed), and the two sets of digests must be the same.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$PWD}
REF="$SRC/tests/data/example-digests.txt"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "$SRC/tests/integration/check.inc"

# run NAME JOB — from the source tree (the examples name their mesh files
# relative to it) or from $T (the homogenize examples read rve-2d.h5 there).
# run NAME DIR JOB: NAME's digests appended to $out; $BLAS: env assignments
run() {
    name=$1
    # shellcheck disable=SC2086
    if (cd "$2" && env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE $BLAS "$PACKD" run "$3" \
        -o "$T/$name.h5" >"$T/$name.json" 2>"$T/$name.err"); then
        sh "$SRC/tests/tools/h5digest.sh" "$T/$name.h5" | sed "s|^|$name |" >>"$out"
    else
        fail "example $name runs" "$(head -c 300 "$T/$name.err")"
    fi
}
run_all() { # OUT
    out=$1
    : >"$out"
    for j in "$SRC"/examples/*.json; do
        run "$(basename "$j" .json)" "$SRC" "$j"
    done
    run rve-2d "$T" "$SRC/examples/homogenize/rve-rsa-2d.json"
    for j in "$SRC"/examples/homogenize/homogenize-*.json; do
        run "$(basename "$j" .json)" "$T" "$j"
    done
}
BLAS=""
run_all "$T/digests.txt"
# The other machine: Prescott's kernel (SSE3, any x86-64) and the other flavour
lib=/usr/lib/x86_64-linux-gnu
flavour=$(readlink -f $lib/libblas.so.3)
other=""
for d in $lib/openblas-serial $lib/openblas-pthread; do
    case $flavour in "$d"/*) ;; *) [ -e "$d/libblas.so.3" ] && other=$d ;; esac
done
BLAS="OPENBLAS_CORETYPE=Prescott${other:+ LD_LIBRARY_PATH=$other}"
run_all "$T/digests-other.txt"
if diff "$T/digests.txt" "$T/digests-other.txt" >"$T/diff-other"; then
    pass "the same digests with $BLAS as with $flavour on this CPU's kernel"
else
    fail "digests depend on the BLAS ($BLAS vs $flavour)" "$(head -10 "$T/diff-other")"
fi
out="$T/digests.txt"

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
