#!/usr/bin/env python3
"""h5md_check.py FILE.h5 [--author NAME] — a packd result checked against the
rules of H5MD 1.1 as docs/result-format.md states them, from h5dump's header
(no h5py needed):

- /h5md: version [1, 1], author with a name (equal to NAME when given; a
  person or "unknown", never the program or a client's address),
  creator, modules/units with its version and system;
- every time-dependent element (a group holding `value`) has `step` and `time`
  whose first dimension equals value's (shared ones through hard links), and
  its `time` a unit ("1" when it is a number, the units module's numeric factor);
- a particles group holds H5MD elements and its box, no other groups; no
  group is a set of per-step copies named 0, 1, …;
- every `unit` attribute is a scalar ASCII string of the units module's
  syntax ("mm", "N mm-2", "s-1"); every dimensional dataset packd writes
  (the DIMENSIONAL list) carries one;
- /connectivity datasets are [n][2] with a particles_group reference.
Prints one line per violation and exits 1 when there is one."""
import re
import subprocess
import sys

# dimensional quantities (absolute paths; an element's value counts as the element)
DIMENSIONAL = [
    r"/particles/[^/]+/(position|radius)", r"/particles/[^/]+/box/edges",
    r"/particles/rve/contact_force",
    r"/observables/(d_min|delta_d|smallest_gap|smallest_wall_gap)",
    r"/observables/timing/[a-z_]+",
    r"/observables/grading/(class_d_lo|class_d_hi|sieve_size)",
    r"/observables/edmd/(delta_d_reached|wall_gap_guaranteed|start_seconds|collisions_per_second)",
    r"/observables/tetfill/(r_min|r_max|overlap_bound|mesh_volume|mesh_edge_mean|mesh_origin"
    r"|seconds_geometric|mesh_nodes)",
    r"/observables/homogenize/(P|sigma|sigma_skew|energy|energy_density|energy_tangential"
    r"|dissipation|sum_force|rve_volume|E_n|friction/E_t|dr/residual|dr/residual_initial"
    r"|tangent/A|tangent/seconds|final_state/position|final_state/fluctuation)",
    r"/observables/fe2/mesh/(nodes|gauss_position|gauss_weight)",
    r"/observables/fe2/(displacement|position|piola_stress|cauchy_stress|von_mises"
    r"|von_mises_element|rve/energy_density|reaction|area|reference_area|E_n"
    r"|newton/solves/abs_residual_0|micro/gauss_point_\d+)",
    r"/connectivity/contact_(overlap|normal_force|branch)",
]
UNIT = re.compile(r"^(\d+(\.\d+)?|(\d+(\.\d+)? )?[A-Za-z]+([+-]\d+)?( [A-Za-z]+([+-]\d+)?)*)$")
# who an author is not: a program, a machine's address
NOT_A_PERSON = re.compile(r"^(packd( run)?|\d+\.\d+\.\d+\.\d+|[0-9a-fA-F:]*:[0-9a-fA-F:.]*)$")


def parse(path):
    """{path: {'kind', 'dims', 'attrs': {name: header text}, 'link'}} from h5dump -H."""
    text = subprocess.run(["h5dump", "-H", path], capture_output=True, text=True,
                          check=True).stdout
    objs = {}
    frames = []  # one per open brace: ('obj', path), ('attr', path, name) or None

    def owner():
        for f in reversed(frames):
            if f and f[0] == "obj":
                return f[1]
        return None

    def in_attr():
        return next((f for f in reversed(frames) if f and f[0] == "attr"), None)

    for line in text.splitlines()[1:]:
        s = line.strip()
        at = in_attr()
        if at:
            objs[at[1]]["attrs"][at[2]] += s + "\n"
        m = re.match(r'^(GROUP|DATASET) "(.*)" \{$', s)
        a = re.match(r'^ATTRIBUTE "(.*)" \{$', s)
        if m and not at:
            name, up = m.group(2), owner()
            full = "/" if name == "/" else (up or "").rstrip("/") + "/" + name
            objs[full] = {"kind": m.group(1), "dims": None, "attrs": {}, "link": None}
            frames.append(("obj", full))
        elif a and not at:
            objs[owner()]["attrs"][a.group(1)] = ""
            frames.append(("attr", owner(), a.group(1)))
        else:
            if not at:
                o = objs.get(owner() or "", None)
                h = re.match(r'^HARDLINK "(.*)"$', s)
                d = re.match(r"^DATASPACE\s+SIMPLE \{ \( ([0-9, ]+) \)", s)
                if o is not None and h:
                    o["link"] = h.group(1)
                elif o is not None and d:
                    o["dims"] = [int(x) for x in d.group(1).split(",")]
                elif o is not None and re.match(r"^DATASPACE\s+SCALAR", s):
                    o["dims"] = []
            for _ in range(s.count("{")):
                frames.append(None)
        for _ in range(s.count("}")):
            if frames:
                frames.pop()
    return objs


def resolved(objs, p):
    o = objs.get(p)
    while o and o["link"]:
        o = objs.get(o["link"])
    return o


def attr_value(path, obj_attr):
    out = subprocess.run(["h5dump", "-a", obj_attr, path], capture_output=True, text=True).stdout
    m = re.search(r'\(0\): "(.*)"', out)
    return m.group(1) if m else None


def main():
    path = sys.argv[1]
    author = sys.argv[sys.argv.index("--author") + 1] if "--author" in sys.argv else None
    objs = parse(path)
    bad = []
    h5md = objs.get("/h5md", {"attrs": {}})
    if "version" not in h5md["attrs"]:
        bad.append("/h5md has no version")
    for g in ("/h5md/author", "/h5md/creator", "/h5md/modules/units"):
        if g not in objs:
            bad.append(g + " missing")
    if "system" not in objs.get("/h5md/modules/units", {"attrs": {}})["attrs"]:
        bad.append("/h5md/modules/units has no system")
    name = attr_value(path, "/h5md/author/name")
    if not name:
        bad.append("/h5md/author has no name")
    elif author is not None and name != author:
        bad.append("/h5md/author name is %r, not %r" % (name, author))
    elif NOT_A_PERSON.match(name):
        bad.append("/h5md/author name %r is no person (\"unknown\" when none is known)" % name)
    elements = 0
    for p, o in objs.items():
        if o["kind"] != "GROUP" or p + "/value" not in objs:
            continue
        elements += 1
        v = resolved(objs, p + "/value")
        for c in ("step", "time"):
            d = resolved(objs, p + "/" + c)
            if d is None:
                bad.append("%s: time-dependent element without %s" % (p, c))
            elif not v["dims"] or d["dims"] != v["dims"][:1]:
                bad.append("%s/%s: shape %s, value %s" % (p, c, d["dims"], v["dims"]))
        t = resolved(objs, p + "/time")
        if t is not None and "unit" not in t["attrs"]:
            bad.append("%s/time: without a unit (\"1\" for a number)" % p)
    # a particles group holds H5MD elements (and its box), not groups of per-step copies
    for p, o in objs.items():
        parts = p.split("/")
        if o["kind"] == "GROUP" and len(parts) == 4 and parts[1] == "particles" and \
                parts[3] != "box" and p + "/value" not in objs:
            bad.append("%s: a group in a particles group that is no H5MD element" % p)
        kids = [q for q in objs if q.rsplit("/", 1)[0] == p and q != p]
        if o["kind"] == "GROUP" and kids and all(re.fullmatch(r"\d+", q.rsplit("/", 1)[1])
                                                 for q in kids):
            bad.append("%s: per-step copies %s, not one time-dependent element" % (p, kids[0]))
    units = 0
    for p, o in objs.items():
        u = o["attrs"].get("unit")
        if u is None:
            continue
        units += 1
        if "H5T_STRING" not in u or "H5T_CSET_ASCII" not in u or "DATASPACE  SCALAR" not in u:
            bad.append("%s: unit is not a scalar ASCII string" % p)
        else:
            val = attr_value(path, p + "/unit")
            if val is None or not UNIT.match(val):
                bad.append("%s: unit %r is not a unit string" % (p, val))
    dimensional = 0
    for p, o in objs.items():
        if o["kind"] != "DATASET" or o["link"]:
            continue
        el = p[:-len("/value")] if p.endswith("/value") else p
        if any(re.fullmatch(r, el) for r in DIMENSIONAL):
            dimensional += 1
            if "unit" not in o["attrs"]:
                bad.append("%s: dimensional, without a unit" % p)
    for p, o in objs.items():
        if p.startswith("/connectivity/") and o["kind"] == "DATASET" and \
                not p.startswith("/connectivity/contact_"):
            if not o["dims"] or len(o["dims"]) != 2 or o["dims"][1] != 2:
                bad.append("%s: connectivity of shape %s, not [n][2]" % (p, o["dims"]))
            if "particles_group" not in o["attrs"]:
                bad.append("%s: no particles_group" % p)
    for b in bad:
        print("h5md: " + b)
    print("h5md: %s: %d time-dependent elements, %d unit attributes, %d dimensional datasets, "
          "author %r%s" % (path, elements, units, dimensional, name,
                           "" if bad else ", every rule holds"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
