#!/bin/sh
# test_cli.sh — packd run / validate / inspect end to end: real result files
# read back with h5dump, every invalid job refused with its pointer and rule.
set -u
PACKD=${PACKD:-build/packd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "${PACKD_SRC:-.}/tests/integration/check.inc"

# 1. every example runs, ends complete, and h5dump reads the H5MD layout
for ex in examples/*.json; do
    b=$(basename "$ex" .json)
    if "$PACKD" run "$ex" -o "$T/$b.h5" >"$T/$b.json" 2>"$T/$b.err" &&
        grep -q '"complete": true' "$T/$b.json" &&
        h5dump -H "$T/$b.h5" >"$T/$b.dump" &&
        grep -q 'GROUP "h5md"' "$T/$b.dump" &&
        grep -q 'DATASET "position"' "$T/$b.dump" &&
        grep -q 'DATASET "radius"' "$T/$b.dump" &&
        grep -q 'DATASET "species"' "$T/$b.dump" &&
        grep -q 'DATASET "edges"' "$T/$b.dump" &&
        grep -q 'DATASET "job"' "$T/$b.dump" &&
        grep -q 'DATASET "smallest_gap"' "$T/$b.dump" &&
        ! ls "$T"/*.tmp.* >/dev/null 2>&1; then
        pass "example_$b"
    else
        fail "example_$b" "$(cat "$T/$b.err")"
    fi
done

# 1b. EDMD's default start is RSA at φ = 0.30 of the box (2D: δ = √(0.30/0.80)),
#     Meier's zero start when asked; both end complete at φ = 0.80 with no overlap
sed 's/"start": "zero", //' examples/edmd-quartz-2d.json >"$T/edmd-default.json"
"$PACKD" run "$T/edmd-default.json" -o "$T/edmd-default.h5" >"$T/edmd-default.out" 2>&1
# the φ(t) history is in the result file, not in the printed summary
"$PACKD" inspect --full "$T/edmd-default.h5" >"$T/edmd-default.insp"
check edmd_default_start_rsa python3 -c "
import json; d=json.load(open('$T/edmd-default.out')); e=d['edmd']
z=json.load(open('$T/edmd-quartz-2d.json'))['edmd']
h=json.load(open('$T/edmd-default.insp'))['observables']['edmd/history/phi']
assert d['complete'] and e['start'] == 'rsa', e['start']
assert abs(e['start_delta'] - (0.30/0.80)**0.5) < 1e-8, e['start_delta']  # sizes in the engine's unit: up to 2^-29 smaller
assert 'history' not in e and abs(h[0] - 0.3) < 1e-9, h[0]
assert z['start'] == 'zero' and 'start_delta' not in z
for r in (d, json.load(open('$T/edmd-quartz-2d.json'))):
    assert r['pairs_below_delta_d'] == 0 and r['smallest_gap'] >= 0 and abs(r['edmd']['phi_final'] - 0.8) < 1e-12
"

# 1c. where RSA cannot place the default start (103 unit spheres in a walled
#     10 x 10 x 1.2 slab: at δ = (0.30/0.45)^(1/3) RSA saturates near 91) the run
#     starts from zero radii and completes; the same δ given by the user fails
#     with the count placed
cat >"$T/slab.json" <<'EOF2'
{"process":"pack","inputs":{"dim":3,"domain":{"box":{"size":[10,10,1.2],"periodic":false}},
 "grading":{"type":"classes","classes":[{"d":1.0,"volume_percent":100}]},"sampling":"discrete",
 "count":103,"phi":{"value":0.45,"refers_to":"resolved"},"algorithm":"edmd","seed":1}}
EOF2
"$PACKD" run "$T/slab.json" -o "$T/slab.h5" >"$T/slab.out" 2>&1
check edmd_default_start_falls_back_to_zero python3 -c "
import json; d=json.load(open('$T/slab.out')); e=d['edmd']
assert d['complete'] and d['count_placed'] == 103 and e['start'] == 'zero', (d['complete'], e['start'])
assert d['pairs_below_delta_d'] == 0 and abs(e['phi_final'] - 0.45) < 1e-12
"
sed 's/"algorithm":"edmd"/"algorithm":"edmd","edmd":{"delta":0.8736}/' "$T/slab.json" >"$T/slab-delta.json"
check edmd_given_delta_short_fails sh -c "! '$PACKD' run '$T/slab-delta.json' -o '$T/slab-delta.h5' 2>'$T/slab-delta.err' &&
    grep -Eq 'placed only (8|9)[0-9] of 103 grains at delta = 0.8736' '$T/slab-delta.err' && [ ! -e '$T/slab-delta.h5' ]"

# 2. H5MD metadata values as h5dump prints them
h5dump -a /h5md/version "$T/din-a16-3d-walled.h5" >"$T/ver" 2>&1
check h5md_version grep -q '(0): 1, 1' "$T/ver"
h5dump -a /particles/grains/box/boundary "$T/meier-quartz-2d.h5" >"$T/bnd" 2>&1
check box_boundary_periodic grep -q '"periodic", "periodic"' "$T/bnd"
h5dump -a /particles/grains/position/unit "$T/din-a16-3d-walled.h5" >"$T/unit" 2>&1
check position_unit grep -q '"mm"' "$T/unit"

# 3. the result's own audit: no pair closer than Δd = 1 mm, no grain closer than 0.5 mm to a wall
"$PACKD" inspect "$T/din-a16-3d-walled.h5" >"$T/insp.json"
check inspect_gap_audit python3 -c "
import json,sys; d=json.load(open('$T/insp.json')); o=d['observables']
assert o['smallest_gap'] >= 1.0 - 1e-9, o['smallest_gap']
assert o['smallest_wall_gap'] >= 0.5 - 1e-9, o['smallest_wall_gap']
assert o['pairs_below_delta_d'] == 0 and d['grains'] == o['count_placed']
assert abs(o['phi_mix'] - 0.40) < 0.01, o['phi_mix']   # one coarse grain overshoot at most
"

# 4. same job + seed → byte-identical particle data; another seed → different
"$PACKD" run examples/fuller-3d-periodic.json -o "$T/again.h5" >/dev/null 2>&1
for ds in position radius species; do
    h5dump -b LE -d /particles/grains/$ds -o "$T/a.$ds" "$T/fuller-3d-periodic.h5" >/dev/null 2>&1
    h5dump -b LE -d /particles/grains/$ds -o "$T/b.$ds" "$T/again.h5" >/dev/null 2>&1
done
check reproducible_same_seed sh -c "cmp -s '$T/a.position' '$T/b.position' && cmp -s '$T/a.radius' '$T/b.radius' && cmp -s '$T/a.species' '$T/b.species' && test -s '$T/a.position'"
sed 's/"seed": 7/"seed": 8/' examples/fuller-3d-periodic.json >"$T/seed8.json"
"$PACKD" run "$T/seed8.json" -o "$T/seed8.h5" >/dev/null 2>&1
h5dump -b LE -d /particles/grains/position -o "$T/c.position" "$T/seed8.h5" >/dev/null 2>&1
check other_seed_differs sh -c "! cmp -s '$T/a.position' '$T/c.position'"

# 5. invalid jobs: exit 1, JSON errors naming the pointer and the rule, never a crash
expect_invalid() { # file pointer rule
    out=$("$PACKD" validate "$1" 2>/dev/null)
    rc=$?
    if [ $rc -eq 1 ] && printf '%s' "$out" | python3 -c "
import json,sys; d=json.load(sys.stdin)
assert d['valid'] is False
assert any(e['pointer']=='$2' and e['rule']=='$3' for e in d['errors']), d['errors']"; then
        pass "invalid_$(basename "$1" .json)"
    else
        fail "invalid_$(basename "$1" .json)" "rc=$rc $out"
    fi
}
# invalid/: broken by the schema alone; infeasible/: schema-valid, refused by the semantic checks
D=tests/data/invalid
F=tests/data/infeasible
expect_invalid $D/phi-ge-1.json /inputs/phi/value exclusiveMaximum
expect_invalid $D/negative-size.json /inputs/domain/box/size/1 exclusiveMinimum
expect_invalid $D/empty-curve.json /inputs/grading/sizes minItems
expect_invalid $F/non-monotonic-sieve.json /inputs/grading/passing/2 nonDecreasing
expect_invalid $D/unknown-field.json /inputs/colour additionalProperties
expect_invalid $D/unknown-preset.json /inputs/grading/name enum
expect_invalid $D/missing-phi-and-count.json /inputs anyOf
expect_invalid $F/wrong-size-count.json /inputs/domain/box/size dim
expect_invalid $F/periodic-box-too-small.json /inputs/domain/box/size/0 periodicSize
expect_invalid $F/too-many-grains.json /inputs/phi maxParticles
expect_invalid $D/unknown-process.json /process enum
expect_invalid $F/dmin-above-dmax.json /inputs/d_min lessThanDmax
n_invalid=$(ls $D/*.json $F/*.json | wc -l)
check every_invalid_file_listed test "$n_invalid" -eq 12

# 6. malformed JSON (NaN is not JSON, nor is a truncated file): clear error, exit 1
printf '{"process": "pack", "inputs": {"dim": 3, "phi": NaN}}' >"$T/nan.json"
out=$("$PACKD" validate "$T/nan.json" 2>/dev/null)
check nan_rejected sh -c "test $? -eq 1 && printf '%s' '$out' | grep -q '\"rule\": \"json\"'"
printf '{"process": "pack", "inp' >"$T/trunc.json"
"$PACKD" run "$T/trunc.json" -o "$T/trunc.h5" >/dev/null 2>&1
rc=$?
check truncated_rejected sh -c "test $rc -eq 1 && ! test -e '$T/trunc.h5'"
"$PACKD" run $D/phi-ge-1.json -o "$T/bad.h5" >/dev/null 2>&1
rc=$?
check run_refuses_invalid sh -c "test $rc -eq 1 && ! test -e '$T/bad.h5'"

# 7. an unreachable target ends cleanly: the file holds what was placed and says so
cat >"$T/over.json" <<'JOB'
{"process": "pack", "inputs": {"dim": 2, "domain": {"box": {"size": [20, 20], "periodic": false}},
 "grading": {"type": "classes", "classes": [{"d": 1.0, "volume_percent": 100}]},
 "phi": {"value": 0.8, "refers_to": "resolved"}, "rsa": {"max_failed_draws": 20000}, "seed": 3}}
JOB
"$PACKD" run "$T/over.json" -o "$T/over.h5" >"$T/over.out" 2>/dev/null
rc=$?
check unreachable_target_ends_cleanly python3 -c "
import json; d=json.load(open('$T/over.out'))
assert $rc == 0 and d['complete'] is False and d['termination_reason'] == 'max_failed_draws', d
assert 0 < d['count_placed'] < d['count_requested'], d
assert d['phi_resolved'] < 0.8
"
"$PACKD" inspect "$T/over.h5" >"$T/over.insp" 2>/dev/null
check unreachable_target_file python3 -c "
import json; d=json.load(open('$T/over.insp')); o=d['observables']
assert o['termination_reason'] == 'max_failed_draws' and d['grains'] == o['count_placed'] < o['count_requested']"

# 7b. XDMF for ParaView, written to another folder than its HDF5 file: it names the file by
# its relative path, every DataItem is a dataset of the stated shape, the grains have cells
mkdir -p "$T/h5dir" "$T/xdir"
(umask 022 && "$PACKD" run examples/meier-quartz-2d.json -o "$T/h5dir/q.h5" --xdmf "$T/xdir/q.xdmf") >"$T/q.out" 2>&1
check xdmf_sidecar python3 tests/tools/xdmf_check.py "$T/xdir/q.xdmf" --points 1000 --paraview
check xdmf_relative_ref grep -q '>../h5dir/q.h5:/particles/grains/position<' "$T/xdir/q.xdmf"
# the sidecar has the result's mode: 0640 (group-readable, not world-readable) under umask 022
check xdmf_mode_as_result sh -c "[ \"\$(stat -c %a '$T/xdir/q.xdmf')\" = \"\$(stat -c %a '$T/h5dir/q.h5')\" ] &&
    [ \"\$(stat -c %a '$T/h5dir/q.h5')\" = 640 ]"

# 8. progress lines are JSON
"$PACKD" run examples/din-a16-3d-walled.json -o "$T/p.h5" --progress >/dev/null 2>"$T/progress"
check progress_json_lines python3 -c "
import json; lines=[l for l in open('$T/progress') if l.startswith('{')]
assert lines, 'no progress'
for l in lines: d=json.loads(l); assert d['stage']=='rsa' and 0 <= d['fraction'] <= 1
"
# 9. `packd --help`: every description starts in one column (on the synopsis's
#    line after two spaces or more, or alone on the next line under a long one)
"$PACKD" --help >"$T/help.txt"
check help_descriptions_aligned python3 -c "
import re
lines = [l.rstrip('\\n') for l in open('$T/help.txt') if l.startswith('  ')]
cols = []
for l in lines:
    if l.startswith('  packd '):
        m = re.search(r'\\S( {2,})\\S', l[2:])
        if m: cols.append(2 + m.end(1))
    else:
        cols.append(len(l) - len(l.lstrip(' ')))
assert len(cols) >= 12 and len(set(cols)) == 1, sorted(set(cols))
"

# 10. a file that cannot be opened is said so, in one form, with exit 1: the job
#     file itself (no JSON line and column), a mesh and an RVE (with the field's
#     pointer); the homogenize examples' RVE names the pack job that makes it
SRC=${PACKD_SRC:-$PWD}
for cmd in validate "run -o x.h5"; do
    (cd "$T" && "$PACKD" $cmd none.json >"$T/nojob.out" 2>"$T/nojob.err")
    rc=$?
    check "missing_job_file_${cmd%% *}" sh -c "test $rc -eq 1 &&
        test \"\$(cat '$T/nojob.err')\" = 'packd: cannot open none.json: No such file or directory' &&
        grep -q '\"rule\": \"file\"' '$T/nojob.out' && ! grep -q 'line -1' '$T/nojob.out'"
done
sed 's|"file": "tests/data/meshes/cylinder41.msh"|"file": "nope.msh"|' examples/tetfill-cylinder.json >"$T/nomesh.json"
mkdir "$T/fe2" # alone: no pack job beside it, no hint
python3 -c "
import json, sys
j = json.load(open('$SRC/examples/fe2/block-taylor.json'))
j['inputs']['micro']['rve'] = {'file': 'rve150.h5'}
json.dump(j, open('$T/fe2/norve.json', 'w'))"
expect_missing() { # name, job, pointer, file, hint (or "")
    for cmd in validate "run -o x.h5"; do
        (cd "$T" && "$PACKD" $cmd "$2" >"$T/miss.out" 2>"$T/miss.err")
        rc=$?
        if [ $rc -eq 1 ] && grep -qx "$2: $3: cannot open $4: No such file or directory (rule [a-z]*)" "$T/miss.err" &&
            grep -q "\"pointer\": \"$3\"" "$T/miss.out" && { [ -z "$5" ] || grep -qxF "$5" "$T/miss.err"; } &&
            { [ -n "$5" ] || ! grep -q 'pack job' "$T/miss.err"; }; then
            pass "missing_${1}_${cmd%% *}"
        else
            fail "missing_${1}_${cmd%% *}" "rc $rc: $(cat "$T/miss.err")"
        fi
    done
}
expect_missing mesh "$T/nomesh.json" /inputs/domain/mesh/file nope.msh ""
H=$SRC/examples/homogenize
expect_missing rve "$H/homogenize-periodic-2d.json" /inputs/rve/file rve-2d.h5 \
    "packd: rve-2d.h5 is the result of a pack job: run $H/rve-rsa-2d.json first: packd run $H/rve-rsa-2d.json -o rve-2d.h5"
expect_missing fe2_rve "$T/fe2/norve.json" /inputs/micro/rve/file rve150.h5 ""

exit 0
