#!/usr/bin/env python3
"""xdmf_check.py XDMF [--points N] [--tets] [--steps S] [--mesh2d E] [--paraview] — check an
XDMF sidecar the way a reader does: every HDF DataItem (also inside a
HyperSlab) names, relative to the XDMF's folder, a dataset of that shape and
number type (read back with h5dump -H); a HyperSlab's count is its stated
shape and lies inside the dataset; every Uniform grid's Topology carries its
connectivity.  --points N: the grains grid has N vertex cells.  --tets: a
Tetrahedron grid is there.  --steps S: a temporal collection of S grids,
each with its Time.  --mesh2d E: an fe2 macro mesh of E cells (ParaView
must see E cells and the point data "displacement").  With --paraview and Debian's pvpython present,
ParaView's Xdmf3 reader opens the file headless and must make points > 0
and cells > 0 (with --points: the grains' N points and N cells; --tets: tet
cells; --steps: S time steps); prints "SKIP paraview: pvpython not installed"
when it is absent.  Exit 0 when all holds."""
import os, re, shutil, subprocess, sys, xml.etree.ElementTree as E

# h5dump's DATATYPE → (XDMF NumberType, Precision)
TYPES = {"H5T_IEEE_F64LE": ("Float", "8"), "H5T_IEEE_F32LE": ("Float", "4"),
         "H5T_STD_I64LE": ("Int", "8"), "H5T_STD_I32LE": ("Int", "4")}
_cache = {}


def header_of(h5, dataset):
    """(shape, h5 type name) of a dataset, from h5dump -H."""
    if (h5, dataset) not in _cache:
        out = subprocess.run(["h5dump", "-H", "-d", dataset, h5], check=True,
                             capture_output=True, text=True).stdout
        m = re.search(r"DATASPACE\s+SIMPLE\s*\{\s*\(\s*([0-9, ]+)\)", out)
        t = re.search(r"DATATYPE\s+(\S+)", out)
        _cache[(h5, dataset)] = ([int(v) for v in m.group(1).split(",")] if m else [],
                                 t.group(1) if t else "")
    return _cache[(h5, dataset)]


def dims(item):
    return [int(v) for v in item.get("Dimensions").split()]


def check_hdf(item, base, path):
    ref, dataset = item.text.strip().rsplit(":", 1)
    h5 = os.path.join(base, ref)
    assert os.path.exists(h5), f"{ref} does not exist beside {path}"
    want = dims(item)
    got, t = header_of(h5, dataset)
    # a [N] dataset may be described as [N 1]
    assert got == want or got + [1] == want, f"{dataset}: XDMF says {want}, file has {got}"
    kind = (item.get("NumberType", "Float"), item.get("Precision", "4"))
    assert TYPES.get(t) == kind, f"{dataset}: XDMF says {kind}, file has {t}"
    return got


def check_slab(slab, base, path):
    sel, data = list(slab.iter("DataItem"))[1:3]
    assert sel.get("Format") == "XML" and data.get("Format") == "HDF", "HyperSlab layout"
    got = check_hdf(data, base, path)
    v = [int(x) for x in sel.text.split()]
    r = len(got)
    start, stride, count = v[:r], v[r:2 * r], v[2 * r:3 * r]
    for k in range(r):
        assert start[k] + stride[k] * (count[k] - 1) < got[k], f"slab {v} outside {got}"
    assert [c for c in count if c != 1] == [d for d in dims(slab) if d != 1], \
        f"slab count {count} is not its Dimensions {dims(slab)}"


def main():
    path = sys.argv[1]
    arg = lambda k: sys.argv[sys.argv.index(k) + 1] if k in sys.argv else None
    want_points = int(arg("--points")) if arg("--points") else None
    want_steps = int(arg("--steps")) if arg("--steps") else None
    want_tets = "--tets" in sys.argv
    want_mesh2d = int(arg("--mesh2d")) if arg("--mesh2d") else None
    base = os.path.dirname(os.path.abspath(path))
    tree = E.parse(path)
    inner = set()
    for slab in tree.iter("DataItem"):
        if slab.get("ItemType") == "HyperSlab":
            check_slab(slab, base, path)
            inner.update(list(slab.iter("DataItem"))[1:])
    for item in tree.iter("DataItem"):
        if item.get("Format") == "HDF" and item not in inner:
            check_hdf(item, base, path)
    grids = [g for g in tree.iter("Grid") if g.get("GridType", "Uniform") == "Uniform"]
    for g in grids:
        topo = g.find("Topology")
        assert topo is not None and topo.find("DataItem") is not None, \
            f"grid {g.get('Name')}: Topology without connectivity"
    if want_points is not None:
        grains = [g for g in grids if g.get("Name") == "grains"]
        assert grains and grains[0].find("Topology").get("NumberOfElements") == str(want_points)
    if want_tets:
        assert any(g.find("Topology").get("TopologyType") == "Tetrahedron" for g in grids), \
            "no Tetrahedron grid"
    if want_steps is not None:
        coll = [g for g in tree.iter("Grid") if g.get("CollectionType") == "Temporal"]
        assert coll, "no temporal collection"
        steps = coll[0].findall("Grid")
        assert len(steps) == want_steps, f"{len(steps)} step grids, want {want_steps}"
        assert all(s.find("Time") is not None for s in steps), "a step grid without Time"
    print(f"xdmf: {len(grids)} grids, every DataItem matches its dataset")
    if "--paraview" in sys.argv:
        paraview(path, want_points, want_tets, want_steps, want_mesh2d)


# Run inside pvpython: counts per block of the reader's output (the last time step).
PV_SCRIPT = """
from paraview.simple import *
from paraview import servermanager as sm
r = Xdmf3ReaderS(FileName=[%r])
times = list(r.TimestepValues) if r.TimestepValues else []
r.UpdatePipeline(times[-1] if times else 0)
i = r.GetDataInformation()
d = sm.Fetch(r)
tets = 0
blocks = [d]
if d.IsA('vtkCompositeDataSet'):
    it = d.NewIterator()
    it.InitTraversal()
    blocks = []
    while not it.IsDoneWithTraversal():
        blocks.append(it.GetCurrentDataObject())
        it.GoToNextItem()
for o in blocks:
    if o is not None and o.IsA('vtkDataSet'):
        tets += sum(o.GetCellType(c) == 10 for c in range(o.GetNumberOfCells()))
arrays = sorted({o.GetPointData().GetArrayName(a) for o in blocks if o is not None and o.IsA('vtkDataSet')
                 for a in range(o.GetPointData().GetNumberOfArrays())})
print('arrays', ','.join(arrays))
print('points', i.GetNumberOfPoints(), 'cells', i.GetNumberOfCells(), 'tets', tets, 'steps', len(times))
"""


def paraview(path, want_points, want_tets, want_steps, want_mesh2d=None):
    pv = shutil.which("pvpython") or shutil.which("pvbatch")
    if not pv:
        print("SKIP paraview: pvpython not installed (Debian's paraview)")
        return
    script = PV_SCRIPT % os.path.abspath(path)
    cmd = [pv, "--force-offscreen-rendering", "-c", script] if pv.endswith("pvpython") else [pv, "-c", script]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    m = re.search(r"points (\d+) cells (\d+) tets (\d+) steps (\d+)", res.stdout)
    assert m, f"pvpython said: {res.stdout[-500:]} {res.stderr[-500:]}"
    pts, cells, tets, steps = (int(m.group(k)) for k in range(1, 5))
    arrays = re.search(r"arrays (\S*)", res.stdout).group(1).split(",")
    print(f"paraview: {pts} points, {cells} cells, {tets} tets, {steps} time steps, point data {arrays}")
    if want_mesh2d is not None:  # an fe2 macro mesh, no grains
        assert cells == want_mesh2d and "displacement" in arrays, (cells, arrays)
        assert want_steps is None or steps == want_steps, f"ParaView sees {steps} time steps"
        return
    assert "radius" in arrays, "ParaView sees no radius"
    assert pts > 0 and cells > 0, "ParaView's Xdmf3 reader made no cells"
    if want_points is not None and not want_tets and want_steps is None:
        assert pts == want_points and cells == want_points, (pts, cells)
    if want_tets:
        assert tets > 0, "ParaView's Xdmf3 reader made no tet cells"
    if want_steps is not None:
        assert steps == want_steps, f"ParaView sees {steps} time steps, want {want_steps}"
        assert "contact_force" in arrays, "ParaView sees no contact_force"


if __name__ == "__main__":
    main()
