#!/bin/sh
# test_placer_added.sh — a method added in its own file and one table row
# runs everywhere a built-in one does: build/tests/test_placer_added is packd
# with the "lattice" placer registered (tests/unit/test_placer_added.c).  It
# validates, runs through `run` (its observables under /observables/lattice
# with their units), and through the daemon, whose process description
# offers it and whose worker (the same binary, exec'd) runs it.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
PACKD="${PACKD_BUILD:-$SRC/build}/tests/test_placer_added"
cat >"$T/lattice.json" <<'JOB'
{"process": "pack", "inputs": {"dim": 2, "unit": "mm",
  "domain": {"box": {"size": [20, 20], "periodic": false}},
  "grading": {"type": "fuller", "q": 0.5, "d_max": 2}, "d_min": 1, "delta_d": 0.1,
  "phi": {"value": 0.2, "refers_to": "resolved"}, "algorithm": "lattice"}}
JOB

"$PACKD" validate "$T/lattice.json" >"$T/v.json"
check lattice_validates test "$(jget "$T/v.json" 'd["valid"]')" = True
"$PACKD" run "$T/lattice.json" -o "$T/l.h5" >"$T/l.json" 2>"$T/l.err"
check lattice_runs test $? -eq 0
check lattice_complete test "$(jget "$T/l.json" 'd["complete"]')" = True
check lattice_pitch_with_unit sh -c "h5dump -a /observables/lattice/pitch/unit '$T/l.h5' | grep -q '\"mm\"'"
check lattice_sites_written sh -c "h5dump -d /observables/lattice/sites '$T/l.h5' | grep -q '(0): 81'"

start_daemon lattice || { fail lattice_daemon_starts; exit 1; }
c -o "$T/desc.json" "$B/processes/pack"
check lattice_in_description test "$(jget "$T/desc.json" '"lattice" in d["inputs"]["algorithm"]["schema"]["enum"]')" = True
body_of "$T/lattice.json" >"$T/body.json"
J=$(submit "$T/body.json")
wait_status "$J" successful 60
check lattice_daemon_successful test "$(status_of "$J")" = successful
c -o "$T/d.h5" "$B/jobs/$J/results/result"
check lattice_daemon_unit sh -c "h5dump -a /observables/lattice/pitch/unit '$T/d.h5' | grep -q '\"mm\"'"
