#!/bin/sh
# test_wall_time.sh — limits.wall_time_s holds within a second or two for a
# large RSA job: 2·10⁶ grains with a 1 s limit (drawing and sorting the sizes
# alone takes about that; the placer's grids would take seconds more) and a
# dense run that is still placing when its 2 s run out.  Each ends with a
# truthful summary: complete false, termination_reason wall_time, the limit
# and the grains placed named in `failure`, the partial result written.
# The sizes stage (one sort) is not interruptible: its time is measured
# (timing.sizes_s) and the bound counts from the later of it and the limit.
. "${PACKD_SRC:-.}/tests/integration/check.inc"
PACKD=${PACKD:-build/packd}
case "$PACKD" in *build-san*) SLOW=4 ;; *) SLOW=1 ;; esac
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# job NAME N PHI LIMIT: a periodic 3D box of N equal spheres at PHI
job() {
    python3 -c "
import json, sys
n, phi, lim = int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
L = (n * 0.5235987756 / phi) ** (1 / 3)
json.dump({'process': 'pack', 'inputs': {'dim': 3, 'unit': 'mm',
  'domain': {'box': {'size': [L, L, L], 'periodic': True}},
  'grading': {'type': 'classes', 'classes': [{'d': 1.0, 'volume_percent': 100}]},
  'sampling': 'discrete', 'count': n, 'phi': {'value': phi, 'refers_to': 'resolved'},
  'algorithm': 'rsa', 'limits': {'wall_time_s': lim}, 'seed': 1}}, open(sys.argv[1], 'w'))
" "$T/$1.json" "$2" "$3" "$4"
}

# run NAME LIMIT: runs it; checks the summary and the time against the limit
run() {
    t0=$(date +%s.%N)
    "$PACKD" run "$T/$1.json" -o "$T/$1.h5" >"$T/$1.sum" 2>"$T/$1.err"
    rc=$?
    t1=$(date +%s.%N)
    python3 - "$T/$1.sum" "$t0" "$t1" "$2" "$SLOW" "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
t0, t1, limit, slow, name = float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
elapsed = t1 - t0
sizes, place = d["timing"]["sizes_s"], d["timing"]["place_s"]
start = max(limit, sizes)
stop = sizes + place
print("# %s: elapsed %.2f s, limit %g s, sizes %.2f s, placing stopped at %.2f s, %d of %d placed"
      % (name, elapsed, limit, sizes, stop, d["count_placed"], d["count_requested"]))
ok = lambda c, what: print(("PASS " if c else "FAIL ") + name + "_" + what)
ok(d["complete"] is False and d["termination_reason"] == "wall_time", "complete_false_wall_time")
ok("limits.wall_time_s = %g s" % limit in d.get("failure", ""), "failure_names_limit")
ok("%d of %d grains placed" % (d["count_placed"], d["count_requested"]) in d["failure"], "failure_counts_grains")
ok(stop <= start + 1.5 * slow, "placing_stops_within_1_5_s")
ok(elapsed <= start + 2.5 * slow, "run_ends_within_2_5_s")
PY
    check "${1}_exit_3_partial_result" sh -c "[ $rc = 3 ] && [ -s '$T/$1.h5' ]"
}

job large 2000000 0.25 1
run large 1
job dense 400000 0.36 2
run dense 2
exit 0
