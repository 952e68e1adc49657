#!/bin/sh
# test_xdmf.sh — the XDMF sidecars of every kind of result (2D and 3D
# packings, tetfill, homogenize load steps, fe2), as ParaView reads them:
# every DataItem's Dimensions and type are its HDF5 dataset's (h5dump), a
# load step's row of an H5MD element its row's shape and byte offset
# (tests/tools/xdmf_check.py); the tetfill sidecar has a Tetrahedron grid,
# the load paths a temporal collection with one grid per step.  Where pvbatch
# is installed (Debian's paraview and python3-paraview), ParaView's Xdmf3 and
# legacy readers open each headless without a complaint and make the points,
# cells, tet cells, named grains/mesh blocks, id and species, the time steps.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$PWD}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "$SRC/tests/integration/check.inc"
X="python3 $SRC/tests/tools/xdmf_check.py"
PV=
if command -v pvbatch >/dev/null 2>&1; then
    PV=--paraview
else
    skip xdmf_paraview "pvbatch not installed (Debian's paraview, python3-paraview): the sidecars are checked against the HDF5 files only"
fi

# packings, 2D and 3D: one vertex cell per grain
for j in meier-quartz-2d:1000 din-a16-3d-walled:; do
    n=${j%%:*}
    if (cd "$SRC" && "$PACKD" run "examples/$n.json" -o "$T/$n.h5" --xdmf "$T/$n.xdmf") >"$T/$n.out" 2>&1; then
        pts=${j#*:}
        check "xdmf_${n}_datasets" $X "$T/$n.xdmf" ${pts:+--points $pts} $PV
    else
        fail "xdmf_${n}_runs" "$(tail -c 300 "$T/$n.out")"
    fi
done

# tetfill: the mesh as a Tetrahedron grid beside the grains
mkdir -p "$T/h5" "$T/x"
if (cd "$SRC" && "$PACKD" run examples/tetfill-box.json -o "$T/h5/tet.h5" --xdmf "$T/x/tet.xdmf") \
    >"$T/tet.out" 2>&1; then
    ntet=$(h5dump -d /observables/tetfill/mesh_tets_count "$T/h5/tet.h5" | sed -n 's/.*(0): \([0-9]*\).*/\1/p')
    check xdmf_tetfill_mesh_grid grep -q "TopologyType=\"Tetrahedron\" NumberOfElements=\"$ntet\"" "$T/x/tet.xdmf"
    check xdmf_tetfill_datasets $X "$T/x/tet.xdmf" --tets $PV
else
    fail xdmf_tetfill_runs "$(tail -c 300 "$T/tet.out")"
fi

# homogenize: one grid per load step, positions and contact forces per step
if (cd "$T" && "$PACKD" run "$SRC/examples/homogenize/rve-rsa-2d.json" -o rve-2d.h5 &&
    "$PACKD" run "$SRC/examples/homogenize/homogenize-periodic-2d.json" -o hom.h5 --xdmf hom.xdmf) \
    >"$T/hom.out" 2>&1; then
    steps=$(h5dump -d /observables/homogenize/steps "$T/hom.h5" | sed -n 's/.*(0): \([0-9]*\).*/\1/p')
    check xdmf_homogenize_steps_stored test "${steps:-0}" -gt 0
    check xdmf_homogenize_temporal grep -q 'CollectionType="Temporal"' "$T/hom.xdmf"
    check xdmf_homogenize_datasets $X "$T/hom.xdmf" --steps "$steps" $PV
else
    fail xdmf_homogenize_runs "$(tail -c 300 "$T/hom.out")"
fi
# fe2: the deformed macro mesh per converged step (3 steps, 4 Q1 elements)
if (cd "$T" && "$PACKD" run "$SRC/tests/data/fe2/block-small.json" -o fe2.h5 --xdmf fe2.xdmf) \
    >"$T/fe2.out" 2>&1; then
    check xdmf_fe2_datasets $X "$T/fe2.xdmf" --steps 3 --mesh2d 4 $PV
else
    fail xdmf_fe2_runs "$(tail -c 300 "$T/fe2.out")"
fi
exit 0
