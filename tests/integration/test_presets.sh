#!/bin/sh
# test_presets.sh — "quality" and "algorithm": "auto" end to end
# (docs/presets.md): through `packd run`, auto picks tetfill for a mesh, rsa
# for a low target and edmd for a high one, and says why in the summary and
# the file (/observables/auto); a draft job takes the draft column of its
# knobs and an explicit knob wins; the model record (summary "model",
# /observables/modelled) of pack and homogenize; one auto job through the
# daemon.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
M="$SRC/tests/data/meshes"

# pack JOBFILE PYTHON-EDITS: a small 3D periodic equal-sphere job
pack() {
    python3 - "$1" "$2" <<'PY'
import json, sys
i = {"dim": 3, "domain": {"box": {"size": [12, 12, 12], "periodic": True}},
     "grading": {"type": "classes", "classes": [{"d": 2, "volume_percent": 100}]},
     "phi": {"value": 0.2, "refers_to": "resolved"}, "algorithm": "auto", "seed": 2}
exec(sys.argv[2])
json.dump({"process": "pack", "inputs": i}, open(sys.argv[1], "w"))
PY
}
run() { "$PACKD" run "$1" -o "$2" --json >"$3" 2>"$3.err"; }
obs() { "$PACKD" inspect "$1" >"$1.json" && jget "$1.json" "d['observables']$2"; }

# 1. auto: a low target -> rsa, a high one -> edmd, a mesh -> tetfill
pack "$T/low.json" ""
run "$T/low.json" "$T/low.h5" "$T/low.out"
check auto_low_rsa test "$(jget "$T/low.out" 'd["algorithm"] == "rsa" and d["auto"]["threshold"] > 0.2 and "below the threshold" in d["auto"]["reason"]')" = True
check auto_low_in_file test "$(obs "$T/low.h5" '["auto/algorithm"] + " " + str(d["observables"]["auto/threshold"] > 0.2)')" = "rsa True"
pack "$T/high.json" 'i["phi"]["value"] = 0.5'
run "$T/high.json" "$T/high.h5" "$T/high.out"
check auto_high_edmd test "$(jget "$T/high.out" 'd["algorithm"] == "edmd" and d["complete"] and d["auto"]["phi_target_shell"] >= d["auto"]["threshold"]')" = True
check auto_high_in_file test "$(obs "$T/high.h5" '["auto/reason"].startswith("target")')" = True
pack "$T/mesh.json" 'i.clear(); i.update({"dim": 3, "domain": {"mesh": {"file": "'"$M"'/cube22.msh"}}, "algorithm": "auto", "tetfill": {"ratio": 3, "max_passes": 2}, "seed": 5})'
run "$T/mesh.json" "$T/mesh.h5" "$T/mesh.out"
check auto_mesh_tetfill test "$(jget "$T/mesh.out" 'd["algorithm"] == "tetfill" and "mesh" in d["auto"]["reason"]')" = True
check auto_mesh_in_file test "$(obs "$T/mesh.h5" '["auto/algorithm"]')" = tetfill

# 2. quality: the draft column of the EDMD jamming stop; an explicit value wins
pack "$T/draft.json" 'i.update({"phi": {"value": 0.3, "refers_to": "resolved"}, "algorithm": "edmd", "quality": "draft", "edmd": {"until": "jammed"}})'
run "$T/draft.json" "$T/draft.h5" "$T/draft.out"
check quality_draft_knobs test "$(jget "$T/draft.out" 'd["edmd"]["reduced_pressure_target"] == 1e4 and d["model"]["quality"] == "draft"')" = True
pack "$T/expl.json" 'i.update({"phi": {"value": 0.3, "refers_to": "resolved"}, "algorithm": "edmd", "quality": "draft", "edmd": {"until": "jammed", "jamming": {"reduced_pressure": 1e5}}})'
run "$T/expl.json" "$T/expl.h5" "$T/expl.out"
check quality_explicit_wins test "$(jget "$T/expl.out" 'd["edmd"]["reduced_pressure_target"]')" = 100000.0

# 3. the model record: 2D pack, d_min's fines; homogenize without extras
"$PACKD" run "$SRC/examples/homogenize/rve-rsa-2d.json" -o "$T/rve-2d.h5" --json >"$T/rve.out" 2>/dev/null
check model_pack_2d test "$(jget "$T/rve.out" 'd["model"]["dim"] == 2 and d["model"]["contacts_stored"] is False')" = True
pack "$T/fines.json" 'i.update({"grading": {"type": "preset", "name": "A16"}, "d_min": 4, "phi": {"value": 0.4, "refers_to": "mix"}, "domain": {"box": {"size": [60, 60, 60], "periodic": True}}})'
run "$T/fines.json" "$T/fines.h5" "$T/fines.out"
check model_fines_left_out test "$(jget "$T/fines.out" 'abs(d["model"]["fines_phi_left_out"] - (d["phi_target_mix"] - d["phi_target_resolved"])) < 1e-12 and d["model"]["fines_mass_fraction"] > 0.3 and d["phi_mix"] > d["phi_resolved"]')" = True
cat >"$T/h.json" <<JOB
{"process": "homogenize", "inputs": {"rve": {"file": "$T/rve-2d.h5"}, "boundary_condition": "periodic",
 "load": {"type": "uniaxial_compression", "axis": 1, "strain": 0.01, "steps": 3}, "contact": {"E_n": 50},
 "initial_state": {"policy": "radius_inflation", "value": 0.3}, "quality": "draft",
 "output": {"frames": false}}}
JOB
run "$T/h.json" "$T/h.h5" "$T/h.out"
check model_homog test "$(jget "$T/h.out" '[d["model"][k] for k in ("dim", "friction", "tangent", "contacts_stored", "frames_stored", "tolerance")] == [2, False, False, False, False, 1e-5]')" = True
check homog_no_frames_written sh -c "! h5ls -r '$T/h.h5' | grep -q '^/particles/rve/position'"
check model_homog_in_file test "$(obs "$T/h.h5" '["modelled/tolerance"]')" = 1e-05

# 4. one auto job through the daemon: the choice in the job's summary
start_daemon presets || exit 1
python3 -c "import json; print(json.dumps({'inputs': json.load(open('$T/high.json'))['inputs']}))" >"$T/body.json"
ID=$(submit "$T/body.json")
check auto_service_done wait_status "$ID" successful 60
c "$B/jobs/$ID/results" >"$T/res.json"
check auto_service test "$(jget "$T/res.json" 'd["summary"]["value"]["algorithm"] == d["summary"]["value"]["auto"]["algorithm"] == "edmd" and "threshold" in d["summary"]["value"]["auto"]["reason"]')" = True
