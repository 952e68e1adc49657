#!/usr/bin/env python3
"""xdmf_check.py XDMF [--points N] [--paraview] — check an XDMF sidecar the
way a reader does: every HDF DataItem names, relative to the XDMF's folder,
a dataset of that shape (read back with h5dump); the Topology carries its
connectivity.  With --paraview and Debian's pvpython present, ParaView's
Xdmf3 reader opens the file and must make N points and N cells; prints
"paraview: skipped (...)" when pvpython is absent.  Exit 0 when all holds."""
import os, re, shutil, subprocess, sys, xml.etree.ElementTree as E


def shape_of(h5, dataset):
    out = subprocess.run(["h5dump", "-H", "-d", dataset, h5], check=True,
                         capture_output=True, text=True).stdout
    m = re.search(r"DATASPACE\s+SIMPLE\s*\{\s*\(\s*([0-9, ]+)\)", out)
    return [int(v) for v in m.group(1).split(",")] if m else []


def main():
    path = sys.argv[1]
    want_points = int(sys.argv[sys.argv.index("--points") + 1]) if "--points" in sys.argv else None
    base = os.path.dirname(os.path.abspath(path))
    tree = E.parse(path)
    topo = tree.find(".//Topology")
    assert topo is not None and topo.find("DataItem") is not None, "Topology without connectivity"
    for item in tree.iter("DataItem"):
        if item.get("Format") != "HDF":
            continue
        ref, dataset = item.text.strip().rsplit(":", 1)
        h5 = os.path.join(base, ref)
        assert os.path.exists(h5), f"{ref} does not exist beside {path}"
        dims = [int(v) for v in item.get("Dimensions").split()]
        got = shape_of(h5, dataset)
        # a [N] dataset may be described as [N 1]
        assert got == dims or got + [1] == dims, f"{dataset}: XDMF says {dims}, file has {got}"
    if want_points is not None:
        assert topo.get("NumberOfElements") == str(want_points), topo.get("NumberOfElements")
    if "--paraview" in sys.argv:
        pv = shutil.which("pvpython") or shutil.which("pvbatch")
        if not pv:
            print("paraview: skipped (pvpython not installed)")
            return
        script = (
            "from paraview.simple import *\n"
            f"r = Xdmf3ReaderS(FileName=[{path!r}])\n"
            "r.UpdatePipeline()\n"
            "i = r.GetDataInformation()\n"
            "print('points', i.GetNumberOfPoints(), 'cells', i.GetNumberOfCells())\n")
        cmd = [pv, "--force-offscreen-rendering", "-c", script] if pv.endswith("pvpython") else [pv, "-c", script]
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        m = re.search(r"points (\d+) cells (\d+)", res.stdout)
        assert m, f"pvpython said: {res.stdout[-500:]} {res.stderr[-500:]}"
        pts, cells = int(m.group(1)), int(m.group(2))
        print(f"paraview: {pts} points, {cells} cells")
        assert pts > 0 and cells > 0, "ParaView's Xdmf3 reader made no cells"
        if want_points is not None:
            assert pts == want_points and cells == want_points, (pts, cells)


if __name__ == "__main__":
    main()
