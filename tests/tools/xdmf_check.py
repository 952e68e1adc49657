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
ParaView (pvbatch, headless) opens the file with each of its readers (Xdmf3ReaderS,
the default; Xdmf3ReaderT; the legacy XDMFReader) without a complaint on stderr and
must make points > 0 and cells > 0 with radius, species and id (with --points: the
grains' N points and N cells; --tets: tet cells, blocks named grains and mesh where
the reader names blocks; --steps: S time steps); prints "SKIP paraview" when
pvbatch is absent.  A Binary DataItem (a row of a time-dependent element, read by
its offset) names its row as Name="/dataset[k]": its shape is the row's and Seek
the row's byte offset (h5dump -p).  Exit 0 when all holds."""
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
    # exactly the dataset's shape: ParaView's readers check ranks ("Number of dimensions in
    # light data description in Xdmf does not match number of dimensions in hdf5 file")
    assert got == want, f"{dataset}: XDMF says {want}, file has {got}"
    kind = (item.get("NumberType", "Float"), item.get("Precision", "4"))
    assert TYPES.get(t) == kind, f"{dataset}: XDMF says {kind}, file has {t}"
    return got


def offset_of(h5, dataset):
    """The byte offset of a contiguous dataset in its file (h5dump -p)."""
    out = subprocess.run(["h5dump", "-p", "-H", "-d", dataset, h5], check=True,
                         capture_output=True, text=True).stdout
    m = re.search(r"CONTIGUOUS\s+SIZE\s+\d+\s+OFFSET\s+(\d+)", out)
    assert m, f"{dataset}: not stored contiguously, no offset"
    return int(m.group(1))


def check_binary(item, base, path):
    """A Binary item names row k of a dataset (Name="/path[k]"): its shape is the
    dataset's without the first dimension and Seek is that row's byte offset."""
    h5 = os.path.join(base, item.text.strip())
    m = re.fullmatch(r"(/\S+)\[(\d+)\]", item.get("Name", ""))
    assert m, f"Binary item {item.get('Name')} names no dataset row"
    dataset, k = m.group(1), int(m.group(2))
    got, t = header_of(h5, dataset)
    assert got[1:] == dims(item), f"{dataset}[{k}]: XDMF says {dims(item)}, a row is {got[1:]}"
    assert k < got[0], f"{dataset}: row {k} of {got[0]}"
    kind = (item.get("NumberType", "Float"), item.get("Precision", "4"))
    assert TYPES.get(t) == kind, f"{dataset}: XDMF says {kind}, file has {t}"
    assert item.get("Endian") == ("Little" if t.endswith("LE") else "Big"), f"{dataset}: endian"
    row = int(kind[1])
    for n in got[1:]:
        row *= n
    want = offset_of(h5, dataset) + k * row
    assert int(item.get("Seek", -1)) == want, f"{dataset}[{k}]: Seek {item.get('Seek')}, row at {want}"


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
        elif item.get("Format") == "Binary":
            check_binary(item, base, path)
        elif item.get("Format") == "XML" and item not in inner:
            n = len(item.text.split())
            want = 1
            for v in dims(item):
                want *= v
            assert n == want, f"inline DataItem of {n} values says {dims(item)}"
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


# Run inside pvbatch, once per reader: counts of the reader's output (the last
# time step), its block names and point arrays.
PV_SCRIPT = """
import sys
from paraview.simple import *
from paraview import servermanager as sm
reader, key = sys.argv[1], sys.argv[2]
r = getattr(sys.modules['paraview.simple'], reader)(**{key: [%r]})
times = list(r.TimestepValues) if r.TimestepValues else []
r.UpdatePipeline(times[-1] if times else 0)
i = r.GetDataInformation()
d = sm.Fetch(r)
blocks, names = [d], []
if d.IsA('vtkCompositeDataSet'):
    it = d.NewIterator()
    it.InitTraversal()
    blocks = []
    while not it.IsDoneWithTraversal():
        md = it.GetCurrentMetaData()
        names.append(md.Get(d.NAME()) if md is not None and md.Has(d.NAME()) else '')
        blocks.append(it.GetCurrentDataObject())
        it.GoToNextItem()
sets = [o for o in blocks if o is not None and o.IsA('vtkDataSet')]
tets = sum(o.GetCellType(c) == 10 for o in sets for c in range(o.GetNumberOfCells()))
arrays = sorted({o.GetPointData().GetArrayName(a) for o in sets
                 for a in range(o.GetPointData().GetNumberOfArrays())})
print('arrays', ','.join(arrays) or '-')
print('blocks', ','.join(n or '?' for n in names) or '-')
print('points', i.GetNumberOfPoints(), 'cells', i.GetNumberOfCells(), 'tets', tets, 'steps', len(times))
"""
# the default Xdmf3 reader, the one that names blocks, and the legacy one
READERS = [("Xdmf3ReaderS", "FileName"), ("Xdmf3ReaderT", "FileName"), ("XDMFReader", "FileNames")]
# what a reader says when the light data and the file disagree
COMPLAINTS = re.compile(r"does not match|unrecognized array type|ERR\||Warning|SIGSEGV|SIGABRT")


def paraview(path, want_points, want_tets, want_steps, want_mesh2d=None):
    pv = shutil.which("pvbatch") or shutil.which("pvpython")
    if not pv:
        print("SKIP paraview: pvbatch not installed (Debian's paraview, python3-paraview)")
        return
    script = PV_SCRIPT % os.path.abspath(path)
    with open(path + ".pv.py", "w") as f:
        f.write(script)
    for reader, key in READERS:
        cmd = [pv, path + ".pv.py", reader, key]
        try:
            res = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        finally:
            if reader == READERS[-1][0]:
                os.remove(path + ".pv.py")
        said = res.stdout + res.stderr
        m = re.search(r"points (\d+) cells (\d+) tets (\d+) steps (\d+)", res.stdout)
        assert m and res.returncode == 0, f"{reader}: {said[-800:]}"
        bad = COMPLAINTS.search(said)
        assert not bad, f"{reader} complains: {said[max(0, bad.start() - 300):bad.end() + 300]}"
        pts, cells, tets, steps = (int(m.group(k)) for k in range(1, 5))
        arrays = re.search(r"arrays (\S*)", res.stdout).group(1).split(",")
        blocks = re.search(r"blocks (\S*)", res.stdout).group(1).split(",")
        print(f"paraview {reader}: {pts} points, {cells} cells, {tets} tets, {steps} time steps, "
              f"point data {arrays}, blocks {blocks}")
        if want_mesh2d is not None:  # an fe2 macro mesh, no grains
            assert cells == want_mesh2d and "displacement" in arrays, (reader, cells, arrays)
            assert want_steps is None or steps == want_steps, f"{reader} sees {steps} time steps"
            continue
        assert "radius" in arrays and "species" in arrays and "id" in arrays, (reader, arrays)
        assert pts > 0 and cells > 0, f"{reader} made no cells"
        if want_points is not None and not want_tets and want_steps is None:
            assert pts == want_points and cells == want_points, (reader, pts, cells)
        if want_tets:
            assert tets > 0, f"{reader} made no tet cells"
            # Xdmf3ReaderS makes one multi-piece data set of a domain's grids (no names)
            if reader != "Xdmf3ReaderS":
                assert blocks == ["grains", "mesh"], f"{reader}: blocks {blocks}"
        if want_steps is not None:
            assert steps == want_steps, f"{reader} sees {steps} time steps, want {want_steps}"
            assert "contact_force" in arrays, f"{reader} sees no contact_force"


if __name__ == "__main__":
    main()
