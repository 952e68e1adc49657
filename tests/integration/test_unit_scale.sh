#!/bin/sh
# test_unit_scale.sh — the same job with every length ×1e-6, ×1 and ×1e6
# computes the same packing (issue 33 item 7): the same count and φ to 1e-12.
# The placers are chaotic at the last bit (a tet fill whose lengths differ by
# one rounding, ×(1 + 1e-15), ended at φ 0.6263 instead of 0.6310; over the
# three units 0.6292 / 0.6310 / 0.6269), so only the same bits give the same
# φ: the filler runs in units of r_min with its lengths kept to 30 bits
# (core/space/length_snap.h). φ is a ratio of volumes computed in the job's
# unit: equal to a few roundings, 1e-12 allows them.
. "${PACKD_SRC:-.}/tests/integration/check.inc"
PACKD=${PACKD:-build/packd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# scaled NAME TEMPLATE: runs TEMPLATE with @L@ = 20·s, @a@ = 0.5·s, @b@ = 1.5·s
# … at s = 1e-6, 1, 1e6; prints "count phi" per scale
scaled() {
    for s in 1e-6 1 1e6; do
        sed "$(awk -v s=$s 'BEGIN { printf "s/@L@/%.17g/g; s/@a@/%.17g/g; s/@b@/%.17g/g", 20 * s, 0.5 * s, 1.5 * s }')" \
            "$T/$1.tmpl" >"$T/$1-$s.json"
        "$PACKD" run "$T/$1-$s.json" -o "$T/$1-$s.h5" >"$T/$1-$s.out" 2>"$T/$1-$s.err" || echo "rc $?"
        echo "$(field "$T/$1-$s.out" count_placed) $(field "$T/$1-$s.out" phi_resolved)"
    done >"$T/$1.res"
    cat "$T/$1.res"
}

same() { # RESULTS: one count and φ within 1e-12 on every line
    awk 'NR == 1 { n = $1; p = $2 } $1 != n || $1 == "rc" || NF != 2 ||
         (p - $2 > 1e-12 * p) || ($2 - p > 1e-12 * p) { bad = 1 } END { exit bad || NR != 3 }' "$1"
}

# examples/tetfill-box.json: a walled 20 mm cube, radii 0.5–1.5, until no sphere fits
cat >"$T/tetfill.tmpl" <<'JOB'
{"process": "pack", "inputs": {"dim": 3, "domain": {"box": {"size": [@L@, @L@, @L@]}},
 "algorithm": "tetfill", "tetfill": {"r_min": @a@, "r_max": @b@, "epsilon": 1e-4, "z_min": 3},
 "seed": 3}}
JOB
scaled tetfill
check tetfill_unit_free same "$T/tetfill.res"

# EDMD to jamming: two classes (d 1.5 and 0.5 s, 50 % each by volume), 2D
# periodic edge 20 s, 150 grains (sizes set by the count and φ 0.5); before:
# φ 0.8600 / 0.8676 / 0.8598 at ×1e-6 / 1 / 1e6
cat >"$T/edmd.tmpl" <<'JOB'
{"process": "pack", "inputs": {"dim": 2, "domain": {"box": {"size": [@L@, @L@], "periodic": true}},
 "grading": {"type": "classes", "classes": [{"d": @b@, "volume_percent": 50}, {"d": @a@, "volume_percent": 50}]},
 "sampling": "discrete", "count": 150, "phi": {"value": 0.5, "refers_to": "resolved"},
 "algorithm": "edmd", "edmd": {"until": "jammed", "growth_rate": 0.02}, "seed": 1}}
JOB
scaled edmd
check edmd_unit_free same "$T/edmd.res"

# A tet fill of a mesh file (the TetGen 6³ cube, radii from the ratio alone,
# i.e. from the mesh's mean edge), in the paper's order of steps: the nodes
# ×1e-6 / 1 / 1e6 and ×(1 + 1e-15) (one rounding) give the same packing —
# measured 13869 spheres, φ 0.6524537672 at R = 3 saturated in the default
# order, and the same bits here at every scale.
M="${PACKD_SRC:-.}/tests/data/meshes"
for s in 1e-6 1 1e6 1.000000000000001; do
    mkdir -p "$T/mesh$s"
    awk -v s="$s" '/^#/ { print; next } !h { print; h = 1; next }
        NF >= 4 { printf "%s %.17g %.17g %.17g", $1, $2 * s, $3 * s, $4 * s
                  for (i = 5; i <= NF; i++) printf " %s", $i; print ""; next } { print }' \
        "$M/cube.node" >"$T/mesh$s/cube.node"
    cp "$M/cube.ele" "$T/mesh$s/"
    cat >"$T/mesh$s/job.json" <<JOB
{"process": "pack", "inputs": {"dim": 3, "domain": {"mesh": {"file": "$T/mesh$s/cube.node"}},
 "algorithm": "tetfill", "tetfill": {"ratio": 3, "max_passes": 4, "trim_after_loci": true}, "seed": 2}}
JOB
    "$PACKD" run "$T/mesh$s/job.json" -o "$T/mesh$s.h5" >"$T/mesh$s.out" 2>"$T/mesh$s.err" || echo "rc $?"
    echo "$(field "$T/mesh$s.out" count_placed) $(field "$T/mesh$s.out" phi_resolved)"
done >"$T/mesh.res"
cat "$T/mesh.res"
# four lines here: the 1e-15 rounding is the fourth scale
awk 'NR == 1 { n = $1; p = $2 } $1 != n || $1 == "rc" || NF != 2 ||
     (p - $2 > 1e-12 * p) || ($2 - p > 1e-12 * p) { bad = 1 } END { exit bad || NR != 4 }' "$T/mesh.res" &&
    pass tetfill_mesh_unit_free || fail tetfill_mesh_unit_free "$(cat "$T/mesh.res")"
