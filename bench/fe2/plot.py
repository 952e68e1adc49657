#!/usr/bin/python3
"""plot.py — the figures and tables of docs/fe2.md from fe2 result files.

    /usr/bin/python3 bench/fe2/plot.py RESULTS_DIR OUT_DIR

RESULTS_DIR holds the result files bench/fe2/run_examples.sh writes, named
    block-<bc>-p<p>-s<seed>.h5, biaxial-<bc>-s<seed>.h5, slope-<bc>-s<seed>.h5
(bc: taylor, restricted_taylor, periodic).  Writes into OUT_DIR:
    block.png     f_v and the dilatancy over u_v per BC and p (thesis Fig. 6.2)
    biaxial.png   f_v and the dilatancy over u_v, Taylor and restricted Taylor (Fig. 6.5)
    biaxial_mises.png  the von Mises field on the deformed mesh (Fig. 6.6)
    slope_mises.png    the same for the slope (Fig. 6.9)
and prints Markdown: the Newton residual sequences of chosen load steps
(Tables 6.1–6.5, 6.7) and the biaxial dilatancy minima.  Reads the files with
h5dump (hdf5-tools) and needs python3-matplotlib; no h5py."""
import glob
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

OBS = "/observables/fe2/"
BC_LABEL = {"taylor": "Taylor", "restricted_taylor": "restricted Taylor", "periodic": "periodic"}


def h5(path, name):
    """Dataset OBS+name of a result file as a nested list (numbers or strings); its
    attributes (units) left out."""
    out = subprocess.run(["h5dump", "-y", "-w", "0", "-A", "0", "-d", OBS + name, path],
                         capture_output=True, text=True, check=True).stdout
    m = re.search(r"DATASPACE\s+(SCALAR|SIMPLE\s*\{\s*\(([^)]*)\))", out)
    shape = [int(x) for x in m.group(2).split(",")] if m.group(2) else []
    data = out[out.index("DATA {") + 6:out.rindex("}")]
    if '"' in data:
        vals = [re.sub(r"\n\s*", "\n", v) for v in re.findall(r'"((?:[^"\\]|\\.)*)"', data)]
    else:
        vals = [float(x) for x in re.findall(r"[-+0-9.eEnaif]+", data) if re.match(r"[-+0-9.]", x)]
    for n in reversed(shape[1:]):
        vals = [vals[i:i + n] for i in range(0, len(vals), n)]
    return vals if shape else vals[0]


class Result:
    def __init__(self, path):
        self.path = path
        name = os.path.basename(path)[:-3]
        m = re.match(r"(block|biaxial|slope)-([a-z_]+?)(?:-p([0-9.]+))?-s(\d+)$", name)
        self.example, self.bc, self.seed = m.group(1), m.group(2), int(m.group(4))
        self.p = float(m.group(3)) if m.group(3) else None
        self.stage = [int(x) for x in h5(path, "load_steps/stage")]
        names = h5(path, "reaction/names")
        self.rnames = names.split("\n") if isinstance(names, str) else names
        self.reaction = h5(path, "reaction/value")  # [step][condition][x, y]
        self.disp = h5(path, "displacement/value")  # [step][node][x, y]
        self.nodes = h5(path, "mesh/nodes")
        self.dil = h5(path, "dilatancy_percent/value")
        self.area = h5(path, "area/value")
        ymax = max(y for _, y in self.nodes)
        self.top = [a for a, (_, y) in enumerate(self.nodes) if abs(y - ymax) < 1e-9 * max(1, ymax)]

    def reaction_y(self, cond):
        k = self.rnames.index(cond)
        return [r[k][1] for r in self.reaction]

    def u_top(self):
        return [-sum(d[a][1] for a in self.top) / len(self.top) for d in self.disp]

    def last_stage(self):
        """Indices of the load steps of the last stage, with the step before it."""
        last = max(self.stage)
        idx = [i for i, s in enumerate(self.stage) if s == last]
        return ([idx[0] - 1] if idx and idx[0] > 0 else []) + idx

    def newton(self):
        """{step: [[relative residuals of each solve (part) of the step]]}."""
        res = h5(self.path, "newton/iterations/relative_residual")
        solve = [int(x) for x in h5(self.path, "newton/iterations/solve")]
        step = [int(x) for x in h5(self.path, "newton/solves/step")]
        out = {}
        for r, s in zip(res, solve):
            parts = out.setdefault(step[s], {})
            parts.setdefault(s, []).append(r)
        return {k: [v[s] for s in sorted(v)] for k, v in out.items()}


def load(d):
    return [Result(p) for p in sorted(glob.glob(os.path.join(d, "*.h5")))]


def curves(ax_f, ax_d, rs, label, color, bottom="bottom_roller"):
    for k, r in enumerate(sorted(rs, key=lambda r: r.seed)):
        idx = r.last_stage()
        u = r.u_top()
        fv = r.reaction_y(bottom)
        kw = dict(color=color, lw=1.4 if k == 0 else 0.7, alpha=1 if k == 0 else 0.5,
                  label=label if k == 0 else None)
        ax_f.plot([u[i] for i in idx], [fv[i] for i in idx], **kw)
        ax_d.plot([u[i] for i in idx], [r.dil[i] for i in idx], **kw)


def plot_block(rs, out):
    bcs = [b for b in BC_LABEL if any(r.bc == b for r in rs)]
    if not bcs:
        return
    fig, ax = plt.subplots(len(bcs), 2, figsize=(9, 2.8 * len(bcs)), squeeze=False)
    colors = {0.1: "tab:blue", 0.2: "tab:orange", 0.3: "tab:green"}
    for i, bc in enumerate(bcs):
        for p in sorted({r.p for r in rs if r.bc == bc}):
            curves(ax[i][0], ax[i][1], [r for r in rs if r.bc == bc and r.p == p],
                   "p = %g" % p, colors.get(p, "k"))
        ax[i][0].set_ylabel("%s\nf_v [N/mm]" % BC_LABEL[bc])
        ax[i][1].set_ylabel("dilatancy Δ [%]")
        ax[i][0].legend(fontsize=8)
    for a in ax[-1]:
        a.set_xlabel("u_v [mm]")
    fig.suptitle("Block 100 × 100 mm, 3 × 3 Q1, 150-grain RVEs (thin lines: other seeds)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "block.png"), dpi=110)
    plt.close(fig)


def plot_biaxial(rs, out):
    if not rs:
        return
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.4))
    for bc, c in (("taylor", "tab:blue"), ("restricted_taylor", "tab:red")):
        curves(ax[0], ax[1], [r for r in rs if r.bc == bc], BC_LABEL[bc], c, bottom="bottom_y")
    ax[0].set_ylabel("f_v [N/mm]")
    ax[1].set_ylabel("dilatancy Δ [%]")
    for a in ax:
        a.set_xlabel("u_v [mm]")
        a.legend(fontsize=8)
    fig.suptitle("Biaxial test 50 × 100 mm, 5 × 10 Q1, 88-grain RVEs, confining 0.2")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "biaxial.png"), dpi=110)
    plt.close(fig)


def mises_panel(ax, r, step, title, scale=1.0):
    elems = h5(r.path, "mesh/elements")
    vm = h5(r.path, "von_mises_element/value")[step]
    d = r.disp[step]
    xy = [(x + scale * d[a][0], y + scale * d[a][1]) for a, (x, y) in enumerate(r.nodes)]
    polys = [[xy[int(a)] for a in e if a >= 0] for e in elems]
    pc = PolyCollection(polys, array=vm, cmap="viridis", edgecolors="k", linewidths=0.2)
    ax.add_collection(pc)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    plt.colorbar(pc, ax=ax, shrink=0.6, label="σ_mises")


def plot_mises(rs, out, name, steps_of, size=(3.6, 4.6), unit="mm"):
    """One panel per (BC, step): steps_of(r) -> [(step index, displacement scale)]."""
    rs = sorted(rs, key=lambda r: (r.bc, r.seed))
    rs = [r for k, r in enumerate(rs) if k == 0 or r.bc != rs[k - 1].bc]  # one seed per BC
    panels = [(r, st, sc) for r in rs for st, sc in steps_of(r)]
    if not panels:
        return
    fig, ax = plt.subplots(1, len(panels), figsize=(size[0] * len(panels), size[1]), squeeze=False)
    for a, (r, step, scale) in zip(ax[0], panels):
        title = "%s, seed %d, load step %d\nu_v (top) = %.2f %s (u × %g)" % (
            BC_LABEL[r.bc], r.seed, step + 1, r.u_top()[step], unit, scale)
        mises_panel(a, r, step, title, scale)
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=110)
    plt.close(fig)


def step_at(r, u):
    """The load step whose u_v is nearest to u."""
    ut = r.u_top()
    return min(range(len(ut)), key=lambda i: abs(ut[i] - u))


def residual_table(r, steps):
    nw = r.newton()
    cols = [s for s in steps if s in nw]
    seqs = [[x for part in nw[s] for x in part] for s in cols]  # a cut step: its parts in a row
    n = max((len(q) for q in seqs), default=0)
    lines = ["| iter | " + " | ".join("mls %d%s" % (s, "*" if len(nw[s]) > 1 else "") for s in cols) + " |",
             "|---|" + "---|" * len(cols)]
    for i in range(n):
        lines.append("| %d | " % (i + 1) + " | ".join("%.3E" % q[i] if i < len(q) else "" for q in seqs) + " |")
    return "\n".join(lines)


def main():
    src, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    rs = load(src)
    block = [r for r in rs if r.example == "block"]
    biax = [r for r in rs if r.example == "biaxial"]
    slope = [r for r in rs if r.example == "slope"]
    plot_block(block, out)
    plot_biaxial(biax, out)
    plot_mises(biax, out, "biaxial_mises.png", lambda r: [(step_at(r, 1.25), 3.0), (len(r.disp) - 1, 3.0)])
    plot_mises(slope, out, "slope_mises.png", lambda r: [(len(r.disp) - 1, 1.0)], (9, 3.6), "m")
    seed0 = min((r.seed for r in rs), default=1)
    for r in block:
        if r.p == 0.2 and r.seed == seed0:
            print("\n#### block, %s, p = 0.2, seed %d\n" % (BC_LABEL[r.bc], r.seed))
            print(residual_table(r, [4, 7, 11, 15, 22, 28]))
    for r in biax + slope:
        if r.seed == seed0:
            print("\n#### %s, %s, seed %d\n" % (r.example, BC_LABEL[r.bc], r.seed))
            print(residual_table(r, [2, 6, 10, 17] if r.example == "biaxial" else [6, 10, 15, 18]))
    print("\n#### summary per run\n")
    print("| run | steps | f_v end [N/mm] | Δ end [%] | Δ min [%] at u_v [mm] | Δ' min [%] |")
    print("|---|---|---|---|---|---|")
    for r in rs:
        idx = r.last_stage()
        u = r.u_top()
        bottom = "bottom_roller" if r.example == "block" else "bottom_y"
        fv = r.reaction_y(bottom) if bottom in r.rnames else [float("nan")] * len(u)
        i = min(idx, key=lambda k: r.dil[k])
        # Δ' counts from the state before the last stage (after the confinement)
        dconf = 100 * (r.area[i] / r.area[idx[0]] - 1)
        print("| %s | %d | %.2f | %.3f | %.3f at %.2f | %.3f |" % (
            os.path.basename(r.path)[:-3], len(r.disp), fv[-1], r.dil[-1], r.dil[i], u[i], dconf))


if __name__ == "__main__":
    main()
