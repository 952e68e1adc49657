#!/bin/sh
# test_fe2.sh — the 'fe2' process end to end: a 2 × 2 Q1 block whose Gauss
# points carry a nested-pack RVE of ~50 grains (Taylor), confined by a
# pressure and pushed down in 3 load steps, through `packd run` and through
# a real daemon on 127.0.0.1; the result read back with h5dump (mesh,
# fields per step, Newton histories, reactions in balance with the load)
# and its XDMF sidecar; invalid inputs refused with 422 naming the field (server paths for the RVE
# and the mesh among them: the daemon never opens a file on a request's word);
# a load step that cannot converge ends the job failed with the step and
# the reason, its partial file kept.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
cd "$T" || exit 1

python3 - "$T" "$SRC" <<'EOF'
import json, sys, copy
t = sys.argv[1]
job = json.load(open(sys.argv[2] + "/tests/data/fe2/block-small.json"))
json.dump(job, open(t + "/job.json", "w"))
json.dump({"inputs": job["inputs"]}, open(t + "/body.json", "w"))
def bad(name, edit):
    j = copy.deepcopy(job["inputs"]); edit(j)
    json.dump({"inputs": j}, open(t + "/bad_" + name + ".json", "w"))
bad("set", lambda i: i["boundary_conditions"][3].update(on="rigth"))
bad("target", lambda i: i["stages"][1]["targets"].update(top=-1))
bad("friction", lambda i: i["micro"].update(friction={"rho_deg": 20}))
bad("rvepath", lambda i: i["micro"].update(rve={"file": "/etc/passwd"}))
bad("meshpath", lambda i: i.update(mesh={"file": "/etc/passwd"}))
bad("conflict", lambda i: i["boundary_conditions"].append(
    {"name": "corner", "type": "displacement", "on": "lower_left", "component": "x"}) or
    i["stages"][0]["targets"].update(corner=0.5))
bad("loaded", lambda i: i["boundary_conditions"].append({"name": "q", "type": "pressure", "on": "top"})
    or i["stages"][0]["targets"].update(q=0.1))
bad("edges", lambda i: i["boundary_conditions"][3].update(on="upper_right"))
bad("rigid", lambda i: i.update(boundary_conditions=i["boundary_conditions"][3:]) or
    i["stages"][1]["targets"].clear())
bad("unit", lambda i: i["micro"]["rve"]["pack"].update(unit="m"))
bad("inverted", lambda i: i.update(mesh={"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "elements": [[0, 3, 2, 1]], "sets": {"left": {"nodes": [0, 3], "edges": [[0, 3]]}}}))
# the push in one increment to 95 % compression, one cut allowed: the RVE cannot follow (the
# confining step may take the cut: it releases the inflated RVE's prestress)
f = copy.deepcopy(job); f["inputs"]["stages"][1] = {"increments": 1, "targets": {"top_y": -9.5}}
f["inputs"]["newton"] = {"max_cuts": 1}
json.dump(f, open(t + "/fail.json", "w"))
# a Gmsh mesh (a Q1 and a triangle, physical groups as sets): a point load at the tip
g = copy.deepcopy(job); g["inputs"]["mesh"] = {"file": sys.argv[2] + "/tests/data/meshes/plate22.msh"}
g["inputs"]["boundary_conditions"] = [
    {"name": "left_x", "type": "displacement", "on": "left", "component": "x"},
    {"name": "bottom_y", "type": "displacement", "on": "bottom side", "component": "y"},
    {"name": "tip", "type": "force", "on": "tip"}]
g["inputs"]["stages"] = [{"increments": 2, "targets": {"tip": [-0.002, 0]}}]
g["inputs"]["initial_stress"] = "balanced"; g["inputs"]["output"] = {}
json.dump(g, open(t + "/gmsh.json", "w"))
# the prestressed start balanced and no load: u = 0 is the equilibrium
z = copy.deepcopy(job); z["inputs"]["initial_stress"] = "balanced"
z["inputs"]["stages"] = [{"increments": 1, "targets": {"p": 0}}]
json.dump(z, open(t + "/balanced.json", "w"))
EOF

# 1. packd run: complete, 3 load steps, the pressure's resultant p·ly = 0.5 held by the left support
"$PACKD" run job.json -o r.h5 --xdmf r.xdmf --json >r.json 2>r.err
check run_complete python3 -c "
import json; s = json.load(open('r.json'))
assert s['complete'] and s['steps'] == 3 and s['gauss_points'] == 16, s
for v in s['reaction_per_step']['left_x']: assert abs(abs(v) - 0.5) < 1e-6, v
b, t = s['reaction_per_step']['bottom_y'], s['reaction_per_step']['top_y']
for x, y in zip(b, t): assert abs(x + y) < 1e-6 * abs(x), (x, y)  # vertical balance
assert len(s['dilatancy_percent_per_step']) == 3"
h5dump -H r.h5 >r.dump 2>&1
check h5_layout sh -c "grep -q 'GROUP \"fe2\"' r.dump &&
    grep -A3 'DATASET \"value\"' r.dump | grep -q '( 3, 9, 2 )' &&
    grep -q 'DATASET \"relative_residual\"' r.dump && grep -q 'GROUP \"gauss_point_5\"' r.dump &&
    grep -q 'DATASET \"radius\"' r.dump"
h5dump -d /observables/fe2/newton/iterations/relative_residual r.h5 >res.dump 2>&1
check newton_history_starts_at_1 grep -q '(0): 1,' res.dump
check xdmf_sidecar sh -c "grep -q 'TopologyType=\"Quadrilateral\"' r.xdmf &&
    test \$(grep -c '<Time ' r.xdmf) -eq 3"
"$PACKD" picture r.h5 -o resp.svg --kind response >/dev/null 2>&1
check picture_response test -s resp.svg
# the default picture of an fe2 result is its macro problem: the deformed
# mesh coloured by the von Mises stress (coloured ink over the mesh, a bar)
"$PACKD" picture r.h5 -o field.png >/dev/null 2>&1
mesh_ink=$(python3 "$SRC/tests/tools/png_fill.py" field.png 50 75 600 550 colour)
check picture_default_is_field python3 -c "
w, h, f = '$mesh_ink'.split()[:3]; assert (w, h) == ('760', '600') and float(f) > 0.2, '$mesh_ink'"
"$PACKD" picture r.h5 --kind packing -o rve.png >/dev/null 2>&1
check picture_rve_on_request test -s rve.png
check xdmf_items_match python3 "$SRC/tests/tools/xdmf_check.py" r.xdmf --steps 3 --mesh2d 4
# H5MD 1.1: the job's unit (mm) on the RVE, the mesh, the fields; plane-strain stress in N mm-2
check h5md_fe2 python3 "$SRC/tests/tools/h5md_check.py" r.h5
check fe2_units sh -c "h5dump -a /particles/grains/box/edges/unit r.h5 | grep -q '\"mm\"' &&
    h5dump -a /observables/fe2/cauchy_stress/value/unit r.h5 | grep -q '\"N mm-2\"' &&
    h5dump -a /observables/fe2/reaction/value/unit r.h5 | grep -q '\"N mm-1\"'"

# 1a. the Gauss points on 2 threads: the same result, bit for bit (the result digest)
"$PACKD" run job.json -o r2.h5 --threads 2 --json >r2.json 2>r2.err
check threads_same_bits python3 -c "
import json; a = json.load(open('r.json')); b = json.load(open('r2.json'))
assert a['result_digest'] == b['result_digest'] and b['threads'] == 2, (a['result_digest'], b)"

# 1c. a Gmsh mesh of a quadrilateral and a triangle: runs, the sidecar's topology is Mixed
"$PACKD" run gmsh.json -o g.h5 --xdmf g.xdmf --json >g.json 2>g.err
check gmsh_mesh_runs python3 -c "
import json; s = json.load(open('g.json'))
assert s['complete'] and s['gauss_points'] == 5 and s['elements'] == 2, s
assert abs(s['reaction_per_step']['left_x'][-1] - 0.002) < 1e-9, s['reaction_per_step']"
check gmsh_xdmf_mixed sh -c "grep -q 'TopologyType=\"Mixed\"' g.xdmf &&
    python3 '$SRC/tests/tools/xdmf_check.py' g.xdmf --steps 2 --mesh2d 2 --paraview"

# 1b. initial_stress balanced: the radius-inflated RVE's prestress does not move an unloaded block
#     (free, the same block expands: the dilatancy of the run above is large)
"$PACKD" run balanced.json -o z.h5 --json >z.json 2>z.err
check initial_stress_balanced python3 -c "
import json; z = json.load(open('z.json')); r = json.load(open('r.json'))
assert z['complete'] and z['dilatancy_percent_per_step'] == [0.0], z
assert r['dilatancy_percent_per_step'][0] > 10, r['dilatancy_percent_per_step']"

# 2. a step that cannot converge: failed (exit 3), the step and reason named, the partial file kept
"$PACKD" run fail.json -o f.h5 --json >f.json 2>f.err
rc=$?
check failed_exit_3 test "$rc" = 3
check failed_names_step python3 -c "
import json; s = json.load(open('f.json'))
assert not s['complete'] and s['steps'] == 1, s
assert 'load step 2 of 2' in s['failure'] and 'stage 1' in s['failure'], s['failure']"
check partial_file_kept sh -c "h5dump -d /observables/fe2/load_steps/step f.h5 | grep -q 'DATASPACE  SIMPLE { ( 1 )'"

# 3. the daemon: the same job, successful, its result downloaded and read back
start_daemon fe2d --workers 1 || { fail serve_starts; exit 1; }
post() { c -o "$2" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$1" "$B/processes/fe2/execution"; }
code=$(post body.json sub.json)
ID=$(member sub.json jobID)
check daemon_accepts test "$code" = 201 -a -n "$ID"
check daemon_successful wait_status "$ID" successful 60
c -o d.h5 "$B/jobs/$ID/results/result"
c -o res.json "$B/jobs/$ID/results"
check daemon_lists_response_picture grep -q 'response.png' res.json
check daemon_lists_field_picture_first python3 -c "
import json; d = json.load(open('res.json')); pics = [k for k in d if k.endswith('.png')]
assert pics and pics[0] == 'field.png', pics"
check daemon_result_read_back sh -c "h5dump -d /observables/fe2/displacement/value d.h5 | grep -q '( 3, 9, 2 )'"

# 3b. the served process description: each input's schema usable alone by a third-party
#     validator (python3-jsonschema), the micro options bundled from homogenize's and pack's schemas
check description_schemas_standalone python3 - "$B" job.json <<'PYEOF'
import json, sys, urllib.request
from jsonschema import validators
B, job = sys.argv[1], json.load(open(sys.argv[2]))
d = json.load(urllib.request.urlopen(B + "/processes/fe2", timeout=20))
for name, value in job["inputs"].items():
    schema = d["inputs"][name]["schema"]
    cls = validators.validator_for(schema)
    cls.check_schema(schema)
    cls(schema).validate(value)
schema = d["inputs"]["micro"]["schema"]
cls = validators.validator_for(schema)
assert list(cls(schema).iter_errors({"rve": {"file": "x"}, "boundary_condition": "voigt"}))
assert list(cls(schema).iter_errors({"rve": {"pack": {"dim": 7}}, "boundary_condition": "taylor"}))
PYEOF

# 4. invalid inputs: 422 naming the field and the rule
has_error() { grep -A1 "\"pointer\": \"$2\"" "$1" | grep -q "\"rule\": \"$3\""; }
for case in set:/inputs/boundary_conditions/3/on:set target:/inputs/stages/1/targets/top:target \
    friction:/inputs/micro/friction:friction conflict:/inputs/boundary_conditions/4:conflict \
    loaded:/inputs/boundary_conditions/4:loadOnPrescribed edges:/inputs/boundary_conditions/3:edges \
    rigid:/inputs/boundary_conditions:rigidMotion inverted:/inputs/mesh:mesh \
    unit:/inputs/micro/rve/pack/unit:semantic rvepath:/inputs/micro/rve/file:serverPath \
    meshpath:/inputs/mesh/file:serverPath; do
    name=${case%%:*}
    rest=${case#*:}
    code=$(post "bad_$name.json" "bad_$name.out")
    check "invalid_${name}_422" sh -c "test '$code' = 422 && grep -A1 '\"pointer\": \"${rest%:*}\"' bad_$name.out | grep -q '\"rule\": \"${rest##*:}\"'"
done
