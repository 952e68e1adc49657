#!/bin/sh
# test_pack_extremes.sh — the pack process's verdicts through the real binary
# and daemon (issue 21): non-finite literals refused with their position by
# `packd run`/`validate` and by POST /processes/pack/execution (400); an
# integer written as a decimal; out of wall time → exit 3 with the partial
# file; maximize delta_d short of the job's delta_d → the file kept, exit 0,
# a warning with the Δd reached.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

job() { # FILE INPUTS
    printf '{"process": "pack", "inputs": %s}\n' "$2" >"$1"
}
MONO='"dim": 2, "domain": {"box": {"size": [20, 20]}}, "grading": {"type": "classes", "classes": [{"d": 2, "volume_percent": 100}]}'

# 1. NaN / Infinity / 1e999: invalid JSON with line and column, exit 1, no file
for lit in NaN Infinity 1e999; do
    job "$T/lit.json" "{$MONO, \"count\": 10, \"delta_d\": $lit}"
    "$PACKD" run "$T/lit.json" -o "$T/lit.h5" >"$T/lit.out" 2>/dev/null
    rc=$?
    check "run_refuses_$lit" sh -c "[ $rc -eq 1 ] && grep -q '\"rule\": \"json\"' '$T/lit.out' &&
        grep -q 'line 1, column [0-9]' '$T/lit.out' && ! test -e '$T/lit.h5'"
done

# 2. 50.0 grains are 50 grains (was: 0 expected, 1 placed)
job "$T/real.json" "{$MONO, \"count\": 50.0, \"seed\": 2.0}"
"$PACKD" run "$T/real.json" -o "$T/real.h5" >"$T/real.out" 2>/dev/null
check integer_as_decimal sh -c "grep -q '\"count_placed\": 50,' '$T/real.out'"

# 3. 1e308 grains: refused naming the field and the rule
job "$T/big.json" "{$MONO, \"count\": 1e308}"
"$PACKD" validate "$T/big.json" >"$T/big.out" 2>/dev/null
rc=$?
check count_1e308_refused sh -c "[ $rc -eq 1 ] && grep -q '\"pointer\": \"/inputs/count\"' '$T/big.out' &&
    grep -q '\"rule\": \"maximum\"' '$T/big.out'"

# 4. out of wall time: failed, exit 3, the partial file written and marked
job "$T/wt.json" '{"dim": 3, "domain": {"box": {"size": [30, 30, 30], "periodic": true}},
 "grading": {"type": "classes", "classes": [{"d": 2, "volume_percent": 100}]},
 "phi": {"value": 0.5, "refers_to": "resolved"}, "algorithm": "edmd", "edmd": {"until": "jammed"},
 "limits": {"wall_time_s": 0.2}}'
"$PACKD" run "$T/wt.json" -o "$T/wt.h5" >"$T/wt.out" 2>"$T/wt.err"
rc=$?
check wall_time_fails_with_partial_file sh -c "[ $rc -eq 3 ] && test -s '$T/wt.h5' &&
    grep -q '\"failure\": \"ran out of wall time' '$T/wt.out' && grep -q 'partial result' '$T/wt.err' &&
    h5dump -d /observables/verdict/status '$T/wt.h5' | grep -q '\"failed\"'"

# 5. maximize delta_d short of the job's delta_d: the maximized packing kept
#    (was: exit 2, no file), complete false, the Δd reached in a warning
job "$T/max.json" "{$MONO, \"count\": 50, \"delta_d\": 1.4, \"algorithm\": \"edmd\",
 \"edmd\": {\"maximize\": \"delta_d\", \"wall_gap\": \"half\"}}"
"$PACKD" run "$T/max.json" -o "$T/max.h5" >"$T/max.out" 2>/dev/null
rc=$?
check maximize_short_keeps_file sh -c "[ $rc -eq 0 ] && test -s '$T/max.h5' &&
    grep -q '\"complete\": false' '$T/max.out' && grep -q 'short of the job.s delta_d = 1.4' '$T/max.out'"

# 6. the service: a body with NaN is a 400 naming the position
start_daemon ext || exit 1
printf '{"inputs": {%s, "count": 10, "delta_d": NaN}}' "$MONO" >"$T/nan-body.json"
code=$(c -o "$T/nan.out" -w '%{http_code}' -H 'Content-Type: application/json' \
    --data-binary "@$T/nan-body.json" "$B/processes/pack/execution")
check service_nan_400 sh -c "[ '$code' = 400 ] && grep -q 'line 1, column [0-9]' '$T/nan.out'"

# 7. the service's max_particles cap holds for a cap written as a decimal
#    (1e11 was no JSON integer to the cap, so the job's own limit stood)
printf '{"inputs": {"dim": 2, "domain": {"box": {"size": [6000, 6000]}}, "grading": {"type": "classes", "classes": [{"d": 1, "volume_percent": 100}]}, "phi": {"value": 0.7, "refers_to": "resolved"}, "limits": {"max_particles": 1e11}}}' >"$T/cap-body.json"
code=$(c -o "$T/cap.out" -w '%{http_code}' -H 'Content-Type: application/json' \
    --data-binary "@$T/cap-body.json" "$B/processes/pack/execution")
check service_cap_decimal_max_particles sh -c "[ '$code' -ge 400 ] && [ '$code' -lt 500 ] && grep -q maxParticles '$T/cap.out'"
