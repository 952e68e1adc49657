#!/bin/sh
# test_xdmf.sh — the XDMF sidecars of a tetfill and a homogenize result, as
# ParaView would read them: every DataItem names a dataset of the stated
# shape and type (tests/tools/xdmf_check.py); the tetfill sidecar has a
# Tetrahedron grid, the homogenize one a temporal collection with one grid
# per load step.  Where pvpython is installed, ParaView's Xdmf3 reader opens
# each headless and makes points, cells, tet cells and the time steps.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$PWD}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "$SRC/tests/integration/check.inc"
X="python3 $SRC/tests/tools/xdmf_check.py"
PV=
if command -v pvpython >/dev/null 2>&1 || command -v pvbatch >/dev/null 2>&1; then
    PV=--paraview
else
    skip xdmf_paraview "pvpython not installed (Debian's paraview): the sidecars are checked against the HDF5 files only"
fi

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
exit 0
