#!/bin/sh
# run.sh BUILD — run every unit test binary in BUILD/tests and every
# tests/integration/*.sh; add up their PASS/FAIL/SKIP lines and end with the
# one line "N passed, N failed, N skipped" (a SKIP is a case that cannot run
# on this machine: neither passed nor failed).  Exit status is non-zero on
# any failure.  A binary or script that dies without printing FAIL counts as
# one failure.
BUILD=${1:-build}
case "$BUILD" in
/*) ;;
*) BUILD="$PWD/$BUILD" ;;
esac
export PACKD="$BUILD/packd"
export PACKD_BUILD="$BUILD"
export PACKD_SRC="$PWD"
passed=0
failed=0
skipped=0
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run_one() { # name, command...
    name=$1
    shift
    start=$(date +%s)
    timeout 600 "$@" >"$log" 2>&1
    rc=$?
    p=$(grep -c '^PASS ' "$log")
    f=$(grep -c '^FAIL ' "$log")
    s=$(grep -c '^SKIP ' "$log")
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        f=1
        echo "FAIL $name (exit $rc without a FAIL line)" >>"$log"
    fi
    passed=$((passed + p))
    failed=$((failed + f))
    skipped=$((skipped + s))
    counts="$p passed"
    [ "$s" -eq 0 ] || counts="$counts, $s skipped"
    if [ "$f" -ne 0 ]; then
        echo "--- $name: $counts, $f failed ($(($(date +%s) - start)) s)"
        cat "$log"
    else
        echo "--- $name: $counts ($(($(date +%s) - start)) s)"
        grep '^SKIP ' "$log"
    fi
}
for t in "$BUILD"/tests/test_*; do
    [ -x "$t" ] || continue
    run_one "$(basename "$t")" "$t"
done
for s in tests/integration/*.sh; do
    [ -f "$s" ] || continue
    run_one "$(basename "$s")" sh "$s"
done
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
