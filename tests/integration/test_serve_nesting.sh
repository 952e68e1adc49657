#!/bin/sh
# test_serve_nesting.sh — deeply nested request bodies: every depth from 100
# to 10 000 of objects, arrays and both mixed, sent to every route that reads
# JSON, gets a 4xx naming the limit, and the daemon stays up (a pointer buffer
# sized by the request crashed it from depth 130).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

start_daemon nest || exit 1

# nested KIND DEPTH: {"inputs": <DEPTH levels>}
nested() {
    python3 - "$1" "$2" <<'PY'
import sys
kind, depth = sys.argv[1], int(sys.argv[2])
s = "{}"
for i in range(depth):
    k = kind if kind != "mixed" else ("object" if i % 2 else "array")
    s = '{"a":' + s + '}' if k == "object" else "[" + s + "]"
print('{"inputs":{"a":' + s + '}}')
PY
}

for route in processes/pack/execution processes/homogenize/execution processes/fe2/execution; do
    for kind in object array mixed; do
        for depth in 100 130 150 1000 10000; do
            nested $kind $depth >"$T/body.json"
            code=$(c -o "$T/out.json" -w '%{http_code}' -H 'Content-Type: application/json' \
                --data-binary @"$T/body.json" "$B/$route")
            case "$code" in
            4??) pass "$route $kind depth $depth: $code" ;;
            *) fail "$route $kind depth $depth: got '$code'" ;;
            esac
            if [ "$kind" = object ] && [ "$depth" = 150 ]; then
                grep -q 'deeper than 64' "$T/out.json" &&
                    pass "$route: the problem names the limit" ||
                    fail "$route: problem does not name the limit: $(head -c 300 "$T/out.json")"
            fi
            kill -0 "$DPID" 2>/dev/null || {
                fail "daemon died at $route $kind depth $depth"
                tail -5 "$LOG"
                :
                exit 1
            }
        done
    done
done
code=$(c -o /dev/null -w '%{http_code}' "$B/healthz")
[ "$code" = 200 ] && pass "daemon healthy after the nested bodies" || fail "healthz $code"

# A job file nested as deep is refused by packd validate too, with the limit.
nested object 150 | sed 's/^{"inputs"/{"process":"pack","inputs"/' >"$T/deep.json"
"$PACKD" validate "$T/deep.json" >"$T/v.out" 2>&1
rc=$?
[ $rc = 1 ] && grep -q 'deeper than 64' "$T/v.out" && pass "packd validate refuses a 150-deep job file (exit 1)" ||
    fail "packd validate on a deep file: exit $rc $(head -c 300 "$T/v.out")"
:
