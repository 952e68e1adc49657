#!/usr/bin/env python3
"""make_examples.py — write the FE² job files of examples/fe2/ (Meier 2009
§6.4, spec §4.6): the rectangular block, the biaxial test and the slope.
The job files are committed; this script is how they were made (the slope's
inline mesh is too long to write by hand).  Run from the repository root:
    python3 bench/fe2/make_examples.py
Options: --p P (block side pressure, default 0.2), --seed S (the RVE's),
--out DIR (default examples/fe2)."""
import argparse
import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Table 5.1 of the thesis: grain counts 1/40/74/35 of d = 0.250/0.160/0.125/
# 0.100 mm in the 150-grain RVE, written as area (2D "volume") percentages.
TABLE_5_1 = [
    {"d": 0.315, "volume_percent": 0.00},
    {"d": 0.250, "volume_percent": 2.41},
    {"d": 0.160, "volume_percent": 39.49},
    {"d": 0.125, "volume_percent": 44.60},
    {"d": 0.100, "volume_percent": 13.50},
]
# box edge for each grain count: the grains of Table 5.1 at their true sizes
# fill φ ≈ 0.80 of it (sizes are scaled to fill exactly φ = 0.80; EDMD then
# grows them on to jamming, φ ≈ 0.84)
BOX = {88: 1.226, 150: 1.6, 700: 3.457}
BC_FILE = {"taylor": "taylor", "restricted_taylor": "restricted-taylor", "periodic": "periodic"}


def rve_pack(n, seed):
    return {
        "dim": 2,
        "unit": "mm",
        "domain": {"box": {"size": [BOX[n], BOX[n]], "periodic": True}},
        "grading": {"type": "classes", "classes": TABLE_5_1},
        "sampling": "discrete",
        "count": n,
        "phi": {"value": 0.80, "refers_to": "resolved"},
        "algorithm": "edmd",
        "edmd": {"start": "zero", "until": "jammed", "masses": "equal"},
        "seed": seed,
    }


# An RVE grown to jamming has contacts at zero overlap: under the relaxing
# boundary conditions (restricted Taylor, periodic) it has no stiffness at
# F̄ = 1, and the first macro tangent is singular.  Inflating every radius by
# 0.1 % jams it with a small prestress (P̄₀ ≈ 0.05 E_n·0.1 %); initial_stress
# "balanced" makes that prestress the equilibrium at u = 0 (the reactions
# count from it), as the thesis's loading starts from rest.
INFLATION = 0.001


def micro(n, bc, seed, E_n):
    return {"rve": {"pack": rve_pack(n, seed)}, "boundary_condition": bc,
            "contact": {"E_n": E_n}, "relaxation": {"tol": 1e-10},
            "initial_state": {"policy": "radius_inflation", "value": INFLATION}}


def newton(bc):
    """Taylor RVEs are exact (no relaxation): Newton reaches 1e-10.  The relaxed
    ones carry the dynamic relaxation's residual (tol 1e-10 of the RVE's
    forces) into P̄ and Ā, which floors the macro residual near 1e-9."""
    return {"rtol": 1e-10 if bc == "taylor" else 1e-8, "max_iter": 20, "line_search": True,
            "max_cuts": 8 if bc == "taylor" else 6}


def pretty(v, indent=0, width=100):
    """JSON with every value that fits in the line on one line."""
    flat = json.dumps(v, ensure_ascii=False, separators=(", ", ": "))
    if len(flat) + indent <= width or not isinstance(v, (dict, list)) or not v:
        return flat
    pad = " " * (indent + 2)
    if isinstance(v, list):
        items = [pad + pretty(x, indent + 2, width) for x in v]
        return "[\n" + ",\n".join(items) + "\n" + " " * indent + "]"
    items = [pad + json.dumps(k) + ": " + pretty(x, indent + 2, width) for k, x in v.items()]
    return "{\n" + ",\n".join(items) + "\n" + " " * indent + "}"


def write(out, name, comment, inputs):
    path = os.path.join(out, name)
    with open(path, "w", encoding="utf-8") as f:
        text = pretty({"process": "fe2", "comment": comment, "inputs": inputs})
        f.write(text + "\n")
    print("wrote", path)


def block(out, bc, p, seed):
    ptxt = ("%g" % p).replace(".", "")
    write(out, "block-%s%s.json" % (BC_FILE[bc], "" if p == 0.2 else "-p" + ptxt),
          "Meier (2009) §6.4.1, rectangular block: 100 × 100 mm in 3 × 3 Q1 (36 RVEs of 150 "
          "grains, Table 5.1), E_n = 50 N/mm, %s RVEs. Rollers on the left and bottom edges; "
          "stage 1 applies the side pressure p = %g N/mm² on the right edge with the top held "
          "at u_v = 0, stage 2 keeps p and pushes the top down to u_v = 3 mm. f_v is the "
          "reaction of the bottom, the dilatancy the change of the deformed mesh's area "
          "(docs/fe2.md)." % (bc.replace("_", " "), p),
          {
              "mesh": {"rectangle": {"size": [100, 100], "elements": [3, 3]}},
              "boundary_conditions": [
                  {"name": "left_roller", "type": "displacement", "on": "left", "component": "x"},
                  {"name": "bottom_roller", "type": "displacement", "on": "bottom", "component": "y"},
                  {"name": "top", "type": "displacement", "on": "top", "component": "y"},
                  {"name": "side_pressure", "type": "pressure", "on": "right"},
              ],
              "stages": [
                  {"name": "confine", "increments": 5, "targets": {"side_pressure": p, "top": 0}},
                  {"name": "compress", "increments": 30, "targets": {"top": -3}},
              ],
              "initial_stress": "balanced",
              "micro": micro(150, bc, seed, 50),
              "newton": newton(bc),
          })


def biaxial(out, bc, seed):
    write(out, "biaxial-%s.json" % BC_FILE[bc],
          "Meier (2009) §6.4.2, biaxial compression: 50 × 100 mm in 5 × 10 Q1 (200 RVEs of 88 "
          "grains, Table 5.1 grading), E = 50 N/mm, %s RVEs. Top and bottom edges clamped "
          "(u_x = 0; u_y = 0 at the bottom, prescribed at the top); stage 1 applies the "
          "confining pressure 0.2 N/mm on the left and right edges, stage 2 keeps it and moves "
          "the top down by 4 mm in 20 load steps (the thesis's RVE snapshots are at 3.5 mm)."
          % bc.replace("_", " "),
          {
              "mesh": {"rectangle": {"size": [50, 100], "elements": [5, 10]}},
              "boundary_conditions": [
                  {"name": "bottom_x", "type": "displacement", "on": "bottom", "component": "x"},
                  {"name": "bottom_y", "type": "displacement", "on": "bottom", "component": "y"},
                  {"name": "top_x", "type": "displacement", "on": "top", "component": "x"},
                  {"name": "top", "type": "displacement", "on": "top", "component": "y"},
                  {"name": "confine_left", "type": "pressure", "on": "left"},
                  {"name": "confine_right", "type": "pressure", "on": "right"},
              ],
              "stages": [
                  {"name": "confine", "increments": 2,
                   "targets": {"confine_left": 0.2, "confine_right": 0.2, "top": 0}},
                  {"name": "compress", "increments": 20, "targets": {"top": -4}},
              ],
              "initial_stress": "balanced",
              "micro": micro(88, bc, seed, 50),
              "newton": newton(bc),
          })


def slope_mesh():
    """A mapped Q1 mesh of a slope (Zienkiewicz & Pande's problem as Meier shows it:
    a crest carrying the footing, a 1:1 slope, a lower bench): columns at the x
    below, ny = 10 rows from y = 0 to the surface height h(x) (38 × 10 = 380 Q1).
    The footing (23.25 m) ends at the crest edge x = 30 m."""
    xs = [0.0]
    for (a, b, n) in [(0, 6.75, 3), (6.75, 30, 12), (30, 45, 10), (45, 60, 13)]:
        xs += [a + (b - a) * (k + 1) / n for k in range(n)]

    def h(x):
        return 20.0 if x <= 30 else (20.0 - (x - 30) if x <= 45 else 5.0)

    ny = 10
    nx = len(xs) - 1
    nodes = [[round(x, 6), round(h(x) * j / ny, 6)] for j in range(ny + 1) for x in xs]
    node = lambda i, j: j * (nx + 1) + i
    elems = [[node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]
             for j in range(ny) for i in range(nx)]
    sets = {
        "bottom": {"nodes": [node(i, 0) for i in range(nx + 1)]},
        "left": {"nodes": [node(0, j) for j in range(ny + 1)]},
        "right": {"nodes": [node(nx, j) for j in range(ny + 1)]},
    }
    footing = [i for i in range(nx) if xs[i] >= 6.75 - 1e-9 and xs[i + 1] <= 30 + 1e-9]
    return xs, nodes, elems, sets, footing, node, ny


def slope(out, seed, n_grains=700):
    xs, nodes, elems, sets, footing, node, ny = slope_mesh()
    F, B, e = -4.0e7, 23.25, 3.875
    x0, x1 = 30 - B, 30.0
    # A rigid footing with the resultant at eccentricity e = B/6 towards the slope
    # presses the ground with a triangular distribution: q(x1) = 2F/B, q(x0) = 0.
    q = lambda x: 2 * F / B * (x - x0) / (x1 - x0)
    bcs = [
        {"name": "bottom_x", "type": "displacement", "on": "bottom", "component": "x"},
        {"name": "bottom_y", "type": "displacement", "on": "bottom", "component": "y"},
        {"name": "left_x", "type": "displacement", "on": "left", "component": "x"},
        {"name": "right_x", "type": "displacement", "on": "right", "component": "x"},
        {"name": "gravity", "type": "gravity", "density": 2.5e3},
    ]
    targets = {}
    total = 0.0
    for k, i in enumerate(footing):
        name = "footing_%02d" % k
        sets[name] = {"edges": [[node(i, ny), node(i + 1, ny)]]}
        t = 0.5 * (q(xs[i]) + q(xs[i + 1]))  # the mean over the edge: exact resultant
        bcs.append({"name": name, "type": "traction", "on": name})
        targets[name] = [0, round(t, 3)]
        total += t * (xs[i + 1] - xs[i])
    assert abs(total - F) < 1e-3 * abs(F), total
    write(out, "slope-taylor.json" if n_grains == 700 else "slope-taylor-%d.json" % n_grains,
          "Meier (2009) §6.4.3, slope stability after Zienkiewicz & Pande: 380 Q1 (a mapped "
          "mesh of a crest, a 1:1 slope and a bench; the thesis's exact geometry is not "
          "printed), RVEs of %d grains (Table 5.1 grading), Taylor, E_n = 2.8e7 N/m, density "
          "2.5e3 kg/m³ (Table 6.6), SI units. Stage 1 applies gravity in one load step; stage 2 "
          "the massless strip footing (23.25 m, ending at the crest) with its eccentric load "
          "-4.0e7 N (eccentricity 3.875 m = B/6: a triangular contact pressure, applied as "
          "tractions on the footing's edges) in 20 load steps." % n_grains,
          {
              "mesh": {"nodes": nodes, "elements": elems, "sets": sets},
              "boundary_conditions": bcs,
              "stages": [
                  {"name": "gravity", "increments": 1, "targets": {"gravity": [0, -9.81]}},
                  {"name": "footing", "increments": 20, "targets": targets},
              ],
              "initial_stress": "balanced",
              "micro": micro(n_grains, "taylor", seed, 2.8e7),
              "newton": newton("taylor"),
          })


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--p", type=float, nargs="*", default=[0.2])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(ROOT, "examples", "fe2"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for bc in BC_FILE:
        for p in a.p:
            block(a.out, bc, p, a.seed)
    for bc in ("taylor", "restricted_taylor"):
        biaxial(a.out, bc, a.seed)
    slope(a.out, a.seed)


if __name__ == "__main__":
    main()
