#!/usr/bin/env python3
"""bench/tradeoff/plot.py — the tables and plots of docs/tradeoffs.md from bench/tradeoff's lines.

usage: plot.py [--data docs/tradeoffs/data] [--out docs/tradeoffs] [--doc docs/tradeoffs.md]

Reads DATA/STUDY.txt (the lines of bench/tradeoff/run.py), writes OUT/STUDY*.png and rewrites
every block of DOC between `<!-- BEGIN table:NAME -->` and `<!-- END table:NAME -->` with the
table NAME computed here (mean ± standard deviation over the seeds; n = number of runs).
"""
import argparse
import math
import os
import re
import statistics

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({"figure.figsize": (6.0, 4.0), "figure.dpi": 100, "savefig.dpi": 100, "font.size": 9,
                     "axes.grid": True, "grid.alpha": 0.3})


def parse_value(v):
    try:
        return int(v)
    except ValueError:
        pass
    try:
        return float(v)
    except ValueError:
        return v


def read(data, file, study=None):
    """The lines of DATA/FILE.txt of study STUDY (default FILE) as dicts."""
    study = study or file
    path = os.path.join(data, file + ".txt")
    rows = []
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        for line in f:
            kv = dict(tok.split("=", 1) for tok in line.split() if "=" in tok)
            if kv.get("bench") == "tradeoff" and kv.get("study") == study:
                rows.append({k: parse_value(v) for k, v in kv.items()})
    return rows


def group(rows, *keys):
    out = {}
    for r in rows:
        out.setdefault(tuple(r[k] for k in keys), []).append(r)
    return out


def ms(values):
    """mean and standard deviation (0 for one value) of the finite values."""
    v = [x for x in values if isinstance(x, (int, float)) and math.isfinite(x)]
    if not v:
        return math.nan, math.nan
    return statistics.fmean(v), (statistics.stdev(v) if len(v) > 1 else 0.0)


def pm(values, fmt="%.3f"):
    m, s = ms(values)
    if math.isnan(m):
        return "–"
    return (fmt + " ± " + fmt) % (m, s)


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        lines.append("| " + " | ".join(str(x) for x in r) + " |")
    return "\n".join(lines)


def errbar(ax, xs, groups, key, label, **kw):
    m = [ms([r[key] for r in g]) for g in groups]
    ax.errorbar(xs, [a for a, _ in m], yerr=[b for _, b in m], label=label, capsize=3, marker="o", ms=4, **kw)


# ---------------------------------------------------------------------------------------------
GRADING_NAME = {"mono": "equal spheres d = 4, 64 mm walled cube",
                "a16_gap": "A16, d_min 2, Δd 1 mm, 48 mm walled cube (φ_M; EDMD wall_gap none)",
                "fuller": "Fuller q 0.5, d 2–16, 80 mm walled cube (φ_eff)"}


def crossing(xs, ya, yb):
    """First x where log(ya) − log(yb) changes sign (linear interpolation); None if it does not."""
    pts = [(x, math.log(a) - math.log(b)) for x, a, b in zip(xs, ya, yb) if a > 0 and b > 0]
    for (x0, d0), (x1, d1) in zip(pts, pts[1:]):
        if d0 < 0 <= d1:
            return x0 + (x1 - x0) * (-d0) / (d1 - d0)
    return None


def algo(data, out, tables):
    rows = read(data, "algo")
    if not rows:
        return
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    trows, brows = [], []
    for ax, grading in zip(axes, ("mono", "a16_gap", "fuller")):
        g = [r for r in rows if r["grading"] == grading]
        if not g:
            continue
        by = group(g, "alg", "target")
        targets = sorted({r["target"] for r in g})
        for alg in ("rsa", "edmd"):
            # a target some seed could not reach is not a time to reach it: drawn apart
            xs = [t for t in targets if (alg, t) in by and all(r["complete"] for r in by[(alg, t)])]
            errbar(ax, xs, [by[(alg, t)] for t in xs], "cpu_s", alg)
            bad = [t for t in targets if (alg, t) in by and not all(r["complete"] for r in by[(alg, t)])]
            if bad:
                ax.plot(bad, [ms([r["cpu_s"] for r in by[(alg, t)]])[0] for t in bad], "x", color="C3", ms=7,
                        label=alg + " (short of the target)")
        ax.set_yscale("log")
        ax.set_xlabel("target φ_M" if grading == "a16_gap" else "target φ")
        ax.set_ylabel("CPU s per packing")
        ax.set_title(GRADING_NAME[grading], fontsize=8)
        ax.legend()
        common = [t for t in targets if ("rsa", t) in by and ("edmd", t) in by and
                  all(r["complete"] for r in by[("rsa", t)] + by[("edmd", t)])]
        ta = [ms([r["cpu_s"] for r in by[("rsa", t)]])[0] for t in common]
        tb = [ms([r["cpu_s"] for r in by[("edmd", t)]])[0] for t in common]
        x = crossing(common, ta, tb)
        if x is not None:
            be = "%.3f" % x
        elif common and all(a < b for a, b in zip(ta, tb)):
            be = "none: RSA faster up to its reach (%.2f complete)" % max(common)
        else:
            be = "none: EDMD faster from %.2f" % min(common) if common else "–"
        brows.append([grading, be, len(by[("rsa", targets[0])])])
        for t in targets:
            ra, ed = by.get(("rsa", t), []), by.get(("edmd", t), [])
            trows.append([grading, "%.3f" % t, pm([r["cpu_s"] for r in ra], "%.2f") if ra else "– (past its reach)",
                          "%d/%d" % (sum(r["complete"] for r in ra), len(ra)) if ra else "–",
                          pm([r["cpu_s"] for r in ed], "%.2f") if ed else "–",
                          "%d/%d" % (sum(r["complete"] for r in ed), len(ed)) if ed else "–",
                          "%.0f" % ms([r["n"] for r in (ed or ra)])[0]])
    fig.tight_layout()
    fig.savefig(os.path.join(out, "algo.png"))
    plt.close(fig)
    tables["algo"] = table(["grading", "target φ", "RSA CPU s", "RSA complete", "EDMD CPU s", "EDMD complete",
                            "grains"], trows)
    tables["breakeven"] = table(["grading", "RSA/EDMD break-even φ (CPU time equal)", "seeds"], brows)


def maxphi(data, out, tables):
    rows = read(data, "maxphi")
    if not rows:
        return
    trows = []
    for (grading, alg), g in sorted(group([r for r in rows if "target" not in r], "grading", "alg").items()):
        trows.append([grading, alg, pm([r["phi"] for r in g], "%.4f"),
                      pm([r["phi_mix"] for r in g], "%.4f") if grading == "a16_gap" else "–",
                      "%.0f" % ms([r["n"] for r in g])[0], pm([r["cpu_s"] for r in g], "%.2f"),
                      ", ".join(sorted({r["reason"] for r in g}))])
    tables["maxphi"] = table(["grading", "algorithm", "largest φ_eff", "φ_M", "grains", "CPU s", "stop"], trows)
    gap = [r for r in rows if "target" in r]
    if gap:
        grows = []
        for (w, t), g in sorted(group(gap, "wall_gap", "target").items()):
            grows.append([w, "%.3f" % t, "%d/%d" % (sum(r["complete"] for r in g), len(g)),
                          pm([r["delta_d_reached"] for r in g], "%.3f"), pm([r["cpu_s"] for r in g], "%.2f")])
        tables["maxphi_gap"] = table(["wall_gap", "target φ_M", "Δd = 1 reached", "Δd reached (mm)", "CPU s"],
                                     grows)


def growth(data, out, tables):
    rows = read(data, "growth")
    if not rows:
        return
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    trows = []
    for grading in ("mono", "a16"):
        by = group([r for r in rows if r["grading"] == grading], "rate")
        xs = sorted(k[0] for k in by)
        errbar(a1, xs, [by[(x,)] for x in xs], "phi", grading)
        errbar(a2, xs, [by[(x,)] for x in xs], "cpu_s", grading)
        for x in xs:
            g = by[(x,)]
            trows.append([grading, "%g" % x, pm([r["phi"] for r in g], "%.4f"), pm([r["cpu_s"] for r in g], "%.2f"),
                          "%.2g" % ms([r["events"] for r in g])[0], pm([r["z"] for r in g], "%.2f"),
                          pm([r["rattlers"] for r in g], "%.3f")])
    for ax, lab in ((a1, "φ_J (reduced pressure 10⁶)"), (a2, "CPU s")):
        ax.set_xscale("log")
        ax.set_xlabel("growth rate γ")
        ax.set_ylabel(lab)
        ax.legend()
    a2.set_yscale("log")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "growth.png"))
    plt.close(fig)
    tables["growth"] = table(["grading", "γ", "φ_J", "CPU s", "events", "z (non-rattlers)", "rattler fraction"],
                             trows)


def stops(data, out, tables):
    rows = read(data, "stops")
    if not rows:
        return
    ref = {r["seed"]: r["phi"] for r in rows if r["crit"] == "pressure" and r["value"] >= 1e12}
    trows, pts = [], []
    order = {"pressure": 0, "delta_phi": 1, "stall": 2}
    for (crit, value), g in sorted(group(rows, "crit", "value").items(), key=lambda kv: (order[kv[0][0]],
                                                                                           -kv[0][1])):
        err = [abs(r["phi"] - ref[r["seed"]]) for r in g if r["seed"] in ref]
        e, _ = ms(err)
        t, _ = ms([r["cpu_s"] for r in g])
        pts.append((crit, value, e, t))
        trows.append([crit, "%g" % value, "%.2e" % e if not math.isnan(e) else "–", pm([r["phi"] for r in g], "%.5f"),
                      pm([r["cpu_s"] for r in g], "%.2f"), "%.2g" % ms([r["pressure"] for r in g])[0],
                      "%d/%d" % (sum(r["complete"] for r in g), len(g))])
    fig, ax = plt.subplots()
    for crit, mk in (("pressure", "o"), ("delta_phi", "s"), ("stall", "^")):
        p = [(t, max(e, 1e-7)) for c, v, e, t in pts if c == crit]
        if p:
            ax.plot([a for a, _ in p], [b for _, b in p], mk + "-", label=crit)
            for (c, v, e, t) in [q for q in pts if q[0] == crit]:
                ax.annotate("%g" % v, (t, max(e, 1e-7)), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("CPU s")
    ax.set_ylabel("|φ − φ_J(p = 10¹²)| (floor 10⁻⁷)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stops.png"))
    plt.close(fig)
    tables["stops"] = table(["criterion", "value", "mean |φ − φ_J|", "φ", "CPU s", "reduced pressure", "jammed"],
                            trows)


def grains(data, out, tables):
    rows = read(data, "grains")
    if not rows:
        return
    by = group(rows, "edge")
    xs = sorted(k[0] for k in by)
    fig, ax = plt.subplots()
    trows = []
    ns = []
    for x in xs:
        g = [r for r in by[(x,)] if r["complete"]]
        ns.append(ms([r["n"] for r in g])[0])
        trows.append(["%g" % x, "%.0f" % ns[-1], pm([r["sieve_max_pp"] for r in g], "%.2f"),
                      pm([r["sieve_l2_pp"] for r in g], "%.2f"), "%d/%d" % (len(g), len(by[(x,)])),
                      pm([r["cpu_s"] for r in g], "%.2f")])
    for key, lab in (("sieve_max_pp", "max"), ("sieve_l2_pp", "L2 (rms)")):
        errbar(ax, ns, [[r for r in by[(x,)] if r["complete"]] for x in xs], key, lab)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("grains")
    ax.set_ylabel("sieve-curve error (percentage points)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "grains.png"))
    plt.close(fig)
    tables["grains"] = table(["edge mm", "grains", "max error pp", "L2 error pp", "complete", "CPU s"], trows)


def stress(data, out, tables):
    rows = read(data, "stress")
    if not rows:
        return
    fig, ax = plt.subplots()
    trows = []
    for bc in ("taylor", "restricted_taylor", "periodic"):
        by = group([r for r in rows if r["bc"] == bc], "n")
        xs, cv = [], []
        for (n,), g in sorted(by.items()):
            ok = [r for r in g if r["complete"]]
            m, s = ms([r["P11"] for r in ok])
            c = s / abs(m) if ok and m else math.nan
            xs.append(n)
            cv.append(c)
            trows.append([bc, n, "%.3f" % m, "%.3f" % s, "%.3f" % c, "%d/%d" % (len(ok), len(g)),
                          pm([r["cpu_s"] for r in g], "%.2f")])
        ax.plot(xs, cv, "o-", label=bc)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("grains in the 2D RVE")
    ax.set_ylabel("spread of P̄₁₁ across seeds (std / |mean|)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stress.png"))
    plt.close(fig)
    tables["stress"] = table(["boundary condition", "grains", "mean P̄₁₁", "std", "std/|mean|", "converged", "CPU s"],
                             trows)


def dmin(data, out, tables):
    rows = read(data, "dmin")
    if not rows:
        return
    by = group(rows, "d_min", "alg")
    ds = sorted({r["d_min"] for r in rows})
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    trows = []
    for d in ds:
        rs, ed, mg = by.get((d, "rsa"), []), by.get((d, "edmd"), []), by.get((d, "edmd_maxgap"), [])
        any_ = rs or ed
        trows.append(["%g" % d, "%.0f" % ms([r["n"] for r in any_])[0], "%.3f" % ms([r["phi"] for r in any_])[0],
                      "%.3f" % ms([r["cut"] for r in any_])[0], pm([r["cpu_s"] for r in rs], "%.2f"),
                      pm([r["cpu_s"] for r in ed], "%.2f"), pm([r["delta_d_reached"] for r in mg], "%.3f"),
                      pm([r["cpu_s"] for r in mg], "%.2f")])
    for alg, lab in (("rsa", "RSA to φ_M 0.50"), ("edmd", "EDMD to φ_M 0.50"), ("edmd_maxgap", "EDMD largest Δd")):
        xs = [d for d in ds if (d, alg) in by]
        errbar(a2, xs, [by[(d, alg)] for d in xs], "cpu_s", lab)
    xs = [d for d in ds if (d, "rsa") in by]
    errbar(a1, xs, [by[(d, "rsa")] for d in xs], "n", "grains")
    a1.set_yscale("log")
    a1.set_ylabel("grains")
    a1b = a1.twinx()
    a1b.plot(xs, [ms([r["phi"] for r in by[(d, "rsa")]])[0] for d in xs], "s--", color="C3", label="φ_eff")
    a1b.set_ylabel("φ_eff at φ_M 0.50")
    a1b.legend(loc="center right")
    a1.legend(loc="upper right")
    a2.set_yscale("log")
    a2.set_ylabel("CPU s")
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.set_xticks(ds)
        ax.set_xticklabels(["%g" % d for d in ds])
        ax.minorticks_off()
        ax.set_xlabel("d_min (mm)")
    a2.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "dmin.png"))
    plt.close(fig)
    tables["dmin"] = table(["d_min mm", "grains", "φ_eff", "mass cut", "RSA CPU s", "EDMD CPU s",
                            "largest Δd (mm)", "its CPU s"], trows)


def relax(data, out, tables):
    rows = read(data, "relax")
    if not rows:
        return
    fig, ax = plt.subplots()
    trows = []
    for solver in ("dr", "newton"):
        by = group([r for r in rows if r["solver"] == solver], "tol")
        tols = sorted((k[0] for k in by), reverse=True)
        e = [ms([r["err"] for r in by[(t,)]])[0] for t in tols]
        c = [ms([r["cpu_s"] for r in by[(t,)]])[0] for t in tols]
        ax.plot(c, [max(x, 1e-12) for x in e], "o-", label=solver)
        for t, x, y in zip(tols, c, e):
            ax.annotate("%g" % t, (x, max(y, 1e-12)), fontsize=7, xytext=(3, 3), textcoords="offset points")
        for t in tols:
            g = by[(t,)]
            trows.append([solver, "%g" % t, "%.1e" % ms([r["err"] for r in g])[0],
                          "%.1e" % ms([r["err_newton"] for r in g])[0], pm([r["cpu_s"] for r in g], "%.2f"),
                          "%.0f" % ms([r["dr_iterations"] for r in g])[0], "%d/%d" % (sum(r["complete"] for r in g),
                                                                                  len(g))])
    ax.set_xlabel("CPU s (4 load steps, periodic 2D RVE)")
    ax.set_yscale("log")
    ax.set_ylabel("error of P̄ vs the same solver at tol 10⁻¹²")
    ax.set_title("labels: relaxation.tol", fontsize=8)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "relax.png"))
    plt.close(fig)
    tables["relax"] = table(["solver", "tol", "error vs own 1e-12", "error vs Newton 1e-12", "CPU s", "DR iterations",
                             "converged"], trows)


def tangent(data, out, tables):
    rows = read(data, "tangent")
    if not rows:
        return
    trows = []
    for (h,), g in sorted(group(rows, "h").items(), reverse=True):
        trows.append(["%g" % h, "%.1e" % ms([r["rel_diff"] for r in g])[0],
                      "%.1e" % max(r["rel_diff"] for r in g), pm([r["fd_cpu_s"] for r in g], "%.3f"),
                      pm([r["analytic_s"] for r in g], "%.4f"), pm([r["base_cpu_s"] for r in g], "%.3f")])
    tables["tangent"] = table(["FD step h", "mean ‖A_FD − A‖/‖A‖", "max", "FD CPU s (8 relaxations)",
                               "analytic tangent s", "the step itself, CPU s"], trows)


def tetfill(data, out, tables):
    rows = read(data, "tetfill")
    if not rows:
        return
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(13, 4))
    trows = []
    for eps in sorted({r["eps"] for r in rows}):
        by = group([r for r in rows if r["eps"] == eps], "ratio")
        xs = sorted(k[0] for k in by)
        for ax, key in ((a1, "phi"), (a2, "z"), (a3, "cpu_s")):
            errbar(ax, xs, [by[(x,)] for x in xs], key, "ε = %g" % eps)
        for x in xs:
            g = by[(x,)]
            trows.append(["%g" % x, "%g" % eps, pm([r["phi"] for r in g], "%.4f"), pm([r["z"] for r in g], "%.2f"),
                          pm([r["z_tangent"] for r in g], "%.2f"), "%.0f" % ms([r["n"] for r in g])[0],
                          pm([r["cpu_s"] for r in g], "%.2f")])
    for ax, lab in ((a1, "φ (filled until no sphere fits)"), (a2, "coordination z (touching, gap ≤ 0)"),
                    (a3, "CPU s")):
        ax.set_xlabel("size ratio R = r_max / r_min")
        ax.set_ylabel(lab)
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "tetfill.png"))
    plt.close(fig)
    tables["tetfill"] = table(["R", "ε", "φ", "z touching", "z tangent", "spheres", "CPU s"], trows)


def totals(data, out, tables):
    trows = []
    for name in ("algo", "maxphi", "growth", "stops", "grains", "stress", "dmin", "relax", "tangent", "tetfill"):
        for r in read(data, name, "total"):
            trows.append([name, r.get("runs", "–"), "%.0f" % r["cpu_s"]])
    if trows:
        trows.append(["all", "", "%.0f" % sum(float(r[2]) for r in trows)])
        tables["totals"] = table(["study", "packd runs", "CPU s"], trows)


def rewrite(doc, tables):
    with open(doc) as f:
        text = f.read()
    for name, body in tables.items():
        pat = re.compile(r"(<!-- BEGIN table:%s -->\n).*?(<!-- END table:%s -->)" % (name, name), re.S)
        text = pat.sub(lambda m: m.group(1) + body + "\n" + m.group(2), text)
    with open(doc, "w") as f:
        f.write(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default="docs/tradeoffs/data")
    ap.add_argument("--out", default="docs/tradeoffs")
    ap.add_argument("--doc", default="docs/tradeoffs.md")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    tables = {}
    for f in (algo, maxphi, growth, stops, grains, stress, dmin, relax, tangent, tetfill, totals):
        f(a.data, a.out, tables)
    if os.path.exists(a.doc):
        rewrite(a.doc, tables)
    for name, body in tables.items():
        print("== %s\n%s\n" % (name, body))


if __name__ == "__main__":
    main()
