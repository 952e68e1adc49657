#!/bin/sh
# test_fuzz.sh — each libFuzzer harness (tests/fuzz/, built by `make
# fuzz-build` into build-fuzz/) runs FUZZ_TEST_SECONDS (default 2) from the
# committed corpus (h5_rve replays its corpus only, see below): no crash, leak, sanitizer report or hang (10 s per
# input).  Skipped, with a message, where clang's fuzzer runtime is missing.
. "${PACKD_SRC:-.}/tests/integration/check.inc"
SRC=${PACKD_SRC:-$(pwd)}
FB=${FUZZ_BUILD:-$SRC/build-fuzz}
S=${FUZZ_TEST_SECONDS:-2}
if [ ! -f "$FB/.fuzzer-ok" ]; then
    why=$(grep -m1 error "$FB/probe.err" 2>/dev/null)
    skip fuzz "no libFuzzer build in $FB: ${why:-clang -fsanitize=fuzzer missing} (apt-get install clang libclang-rt-14-dev libomp-14-dev)"
    exit 0
fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
for f in "$SRC"/tests/fuzz/fuzz_*.c; do
    t=$(basename "$f" .c)
    t=${t#fuzz_}
    if [ ! -x "$FB/fuzz_$t" ]; then
        fail "fuzz_$t" "not built (make fuzz-build)"
        continue
    fi
    mkdir -p "$T/$t"
    # h5_rve mutates into files that crash inside libhdf5 1.10.8 itself
    # (tests/fuzz/hdf5-known/): here it only replays its corpus, so the suite
    # stays deterministic; `make fuzz` mutates it
    mode="-max_total_time=$S"
    [ "$t" = h5_rve ] && mode="-runs=0"
    if "$FB/fuzz_$t" "$mode" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$T/crash-" \
        "$T/$t" "$SRC/tests/fuzz/corpus/$t" >"$T/$t.log" 2>&1; then
        pass "fuzz_$t ($(sed -n 's/^Done \([0-9]*\) runs.*/\1/p' "$T/$t.log") runs)"
    else
        tail -n 30 "$T/$t.log"
        fail "fuzz_$t"
    fi
done
exit 0
