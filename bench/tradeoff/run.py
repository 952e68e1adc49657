#!/usr/bin/env python3
"""bench/tradeoff — time against accuracy for every speed knob of packd.

Runs `packd run --json` on the job files of bench/tradeoff/jobs/ (each study varies a
few inputs of one of them over several seeds) and prints one machine-readable line per
run:
    bench=tradeoff study=STUDY key=value ... cpu_s=S
cpu_s is the CPU time (user + system) of the `packd run` child, HDF5 output included:
the machine is shared, wall time wanders, CPU time does not (much).  Each study also
writes its lines to DIR/STUDY.txt (--data DIR), which bench/tradeoff/plot.py turns into
the tables and plots of docs/tradeoffs.md.

usage: run.py [--packd build/packd] [--data docs/tradeoffs/data] [--seeds N] [STUDY ...]
studies: algo maxphi growth stops grains stress dmin relax tangent tetfill (default: all)
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
JOBS = os.path.join(HERE, "jobs")


class Runner:
    def __init__(self, packd, tmp):
        self.packd = packd
        self.tmp = tmp
        self.count = 0

    def run(self, job, keep=None, full=False):
        """Run a job; return (summary, cpu seconds, observables or None)."""
        self.count += 1
        path = os.path.join(self.tmp, "job%d.json" % self.count)
        out = keep or os.path.join(self.tmp, "out%d.h5" % self.count)
        with open(path, "w") as f:
            json.dump(job, f)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        p = subprocess.run([self.packd, "run", path, "-o", out, "--json"], capture_output=True, text=True,
                           cwd=self.tmp)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if p.returncode not in (0, 3):
            sys.stderr.write("packd run failed (%d): %s\n%s\n" % (p.returncode, json.dumps(job), p.stderr))
            return None, cpu, None
        summary = json.loads(p.stdout)
        obs = None
        if full:
            q = subprocess.run([self.packd, "inspect", out, "--full"], capture_output=True, text=True, check=True)
            obs = json.loads(q.stdout)["observables"]
        if keep is None:
            os.unlink(out)
        os.unlink(path)
        return summary, cpu, obs


def load(name):
    with open(os.path.join(JOBS, name)) as f:
        job = json.load(f)
    job.pop("comment", None)
    return job


def fmt(v):
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return "%.6g" % v
    return str(v)


class Out:
    def __init__(self, data):
        self.data = data
        self.files = {}

    def line(self, study, file=None, **kv):
        """One line on stdout and in DATA/FILE.txt (FILE: the study's own name by default)."""
        text = "bench=tradeoff study=%s %s" % (study, " ".join("%s=%s" % (k, fmt(v)) for k, v in kv.items()))
        print(text, flush=True)
        file = file or study
        if self.data:
            if file not in self.files:
                self.files[file] = open(os.path.join(self.data, file + ".txt"), "w")
            self.files[file].write(text + "\n")
            self.files[file].flush()


def pack_fields(s):
    """The figures every pack line carries."""
    return dict(n=s.get("count_placed", 0), phi=s.get("phi_resolved", 0.0), phi_mix=s.get("phi_mix", 0.0),
                complete=bool(s.get("complete")), reason=s.get("termination_reason", "?"))


# ---- algorithm for a target φ: time to reach it, per grading ------------------------------
ALGO_CASES = [
    # grading, job file, φ refers to, targets
    ("mono", "mono-walled.json", "resolved", [0.25, 0.30, 0.33, 0.35, 0.37, 0.45, 0.55]),
    ("a16_gap", "a16-gap-walled.json", "mix", [0.36, 0.40, 0.43, 0.46, 0.48, 0.50]),
    ("fuller", "fuller-walled.json", "resolved", [0.55, 0.58, 0.60, 0.62, 0.64]),
]
# RSA above these costs minutes per run (N^F = 10^6 draws per grain near saturation);
# its saturation φ is measured in `maxphi` instead.
RSA_CAP = {"mono": 0.37, "a16_gap": 0.48, "fuller": 0.64}


def algo_job(base, alg, grading):
    job = json.loads(json.dumps(base))
    job["inputs"]["algorithm"] = alg
    if alg == "edmd" and grading == "a16_gap":
        # Titscher §6.3: the true sizes from an RSA start, a shell Δd/2 grown to the job's Δd,
        # Δd between grains only (walls may be touched).
        job["inputs"]["edmd"] = {"growth": "shell", "wall_gap": "none"}
    return job


def study_algo(r, out, seeds):
    for grading, fname, _, targets in ALGO_CASES:
        base = load(fname)
        for target in targets:
            for alg in ("rsa", "edmd"):
                if alg == "rsa" and target > RSA_CAP[grading] + 1e-9:
                    continue
                for seed in range(1, seeds + 1):
                    job = algo_job(base, alg, grading)
                    job["inputs"]["phi"]["value"] = target
                    job["inputs"]["seed"] = seed
                    s, cpu, _ = r.run(job)
                    if s is None:
                        continue
                    out.line("algo", grading=grading, alg=alg, target=target, seed=seed, **pack_fields(s),
                             cpu_s=cpu)


# ---- the largest φ each algorithm reaches ------------------------------------------------
# RSA: targets in steps of 0.01 from START until the first that RSA cannot complete (a target
# above RSA's reach draws more coarse grains, which then fail first: RSA's largest φ is that of
# the last complete target, as Titscher's success rate ψ counts it).
RSA_SWEEP = {"mono": 0.30, "a16_gap": 0.42, "fuller": 0.62}


def study_maxphi(r, out, seeds):
    for grading, fname, _, _ in ALGO_CASES:
        base = load(fname)
        # the boxes of `algo` cost minutes at saturation and jamming: smaller ones here
        if grading == "fuller":
            base["inputs"]["domain"]["box"]["size"] = [48, 48, 48]
        if grading == "mono":
            base["inputs"]["domain"]["box"]["size"] = [32, 32, 32]
        for seed in range(1, seeds + 1):
            target, best, cpu_all = RSA_SWEEP[grading], None, 0.0
            while target < 0.9:
                job = algo_job(base, "rsa", grading)
                job["inputs"]["phi"]["value"] = target
                job["inputs"]["seed"] = seed
                s, cpu, _ = r.run(job)
                cpu_all += cpu
                if s is None or not s.get("complete"):
                    break
                best = (target, s, cpu)
                target = round(target + 0.01, 4)
            if best is not None:
                out.line("maxphi", grading=grading, alg="rsa", seed=seed, **pack_fields(best[1]),
                         next_phi=s.get("phi_resolved", 0.0) if s else 0.0, cpu_s=best[2], sweep_cpu_s=cpu_all)
        for alg in ("edmd", "tetfill"):
            if alg == "edmd" and grading == "a16_gap":
                continue  # bounded by the gap, not by jamming: the target sweep below
            if alg == "tetfill" and grading != "mono":
                continue
            for seed in range(1, seeds + 1):
                job = algo_job(base, alg, grading)
                inp = job["inputs"]
                inp["seed"] = seed
                if alg == "edmd":
                    inp["phi"]["value"] = 0.5
                    inp["edmd"] = {"until": "jammed", "jamming": {"reduced_pressure": 1e6}}
                else:
                    # tet filling makes its own sizes: the narrowest size range (R = 1.5)
                    # around the same mean diameter
                    job["inputs"] = {"dim": 3, "domain": {"box": {"size": inp["domain"]["box"]["size"]}},
                                     "algorithm": "tetfill", "tetfill": {"r_min": 1.6, "r_max": 2.4}, "seed": seed}
                s, cpu, _ = r.run(job)
                if s is None:
                    continue
                out.line("maxphi", grading=grading, alg=alg, seed=seed, **pack_fields(s), cpu_s=cpu)
    # A16 with Δd: EDMD shell growth to φ_M targets; the largest φ_M with Δd reached
    # (wall_gap half: Δd/2 at the walls, RSA's rule on this branch; none: Titscher's)
    base = load("a16-gap-walled.json")
    for wall_gap, targets in (("half", (0.46, 0.48, 0.50, 0.52)), ("none", (0.50, 0.52, 0.54, 0.56))):
        for target in targets:
            for seed in range(1, seeds + 1):
                job = algo_job(base, "edmd", "a16_gap")
                job["inputs"]["edmd"]["wall_gap"] = wall_gap
                job["inputs"]["phi"]["value"] = target
                job["inputs"]["seed"] = seed
                s, cpu, _ = r.run(job)
                if s is None:
                    continue
                out.line("maxphi", grading="a16_gap", alg="edmd", wall_gap=wall_gap, target=target, seed=seed,
                         **pack_fields(s), delta_d_reached=s.get("edmd", {}).get("delta_d_reached", 0.0),
                         cpu_s=cpu)


# ---- EDMD growth rate vs φ_J and time ------------------------------------------------------
def edmd_fields(s):
    e = s.get("edmd", {})
    return dict(events=e.get("events", 0), pressure=e.get("reduced_pressure", 0.0),
                z=e.get("mean_contact_number", 0.0), rattlers=e.get("rattler_fraction", 0.0),
                criterion=e.get("termination_criterion", "?"))


GROWTH_N = 500


def study_growth(r, out, seeds):
    # A16 needs 1000 grains in its 48 mm periodic cube: fewer could grow past half an edge
    for grading, fname, n in (("mono", "mono-periodic.json", GROWTH_N), ("a16", "a16-periodic.json", 1000)):
        base = load(fname)
        for rate in (0.003, 0.01, 0.03, 0.1, 0.3):
            if grading == "a16" and rate < 0.01:
                continue  # ~30 CPU s a run
            for seed in range(1, seeds + 1):
                job = json.loads(json.dumps(base))
                inp = job["inputs"]
                inp["count"] = n
                inp["seed"] = seed
                inp["edmd"] = {"until": "jammed", "growth_rate": rate, "jamming": {"reduced_pressure": 1e6}}
                s, cpu, _ = r.run(job)
                if s is None:
                    continue
                out.line("growth", grading=grading, rate=rate, seed=seed, **pack_fields(s), **edmd_fields(s),
                         cpu_s=cpu)


# ---- jamming stop criteria vs the error in φ_J --------------------------------------------
STOPS = [
    ("pressure", 1e12, {"reduced_pressure": 1e12}),  # the reference
    ("pressure", 1e9, {"reduced_pressure": 1e9}),
    ("pressure", 1e6, {"reduced_pressure": 1e6}),
    ("pressure", 1e4, {"reduced_pressure": 1e4}),
    ("delta_phi", 1e-5, {"delta_phi": 1e-5}),
    ("delta_phi", 1e-7, {"delta_phi": 1e-7}),
    ("delta_phi", 1e-9, {"delta_phi": 1e-9}),
    ("stall", 1e-6, None),
    ("stall", 1e-8, None),
]


def study_stops(r, out, seeds):
    base = load("mono-periodic.json")
    for crit, value, jam in STOPS:
        for seed in range(1, seeds + 1):
            job = json.loads(json.dumps(base))
            inp = job["inputs"]
            inp["count"] = GROWTH_N
            inp["seed"] = seed
            e = {"until": "jammed", "growth_rate": 0.01}
            if jam is None:
                e["stall"] = {"growth": value}
            else:
                e["jamming"] = jam
            inp["edmd"] = e
            s, cpu, _ = r.run(job)
            if s is None:
                continue
            out.line("stops", crit=crit, value=value, seed=seed, **pack_fields(s), **edmd_fields(s), cpu_s=cpu)


# ---- number of grains vs the sieve-curve error ---------------------------------------------
def sieve_errors(s):
    """Max and L2 distance (percentage points) between target and achieved passing fractions
    at the sieve sizes of the modelled range (the upper sieve of each class but the top)."""
    cls = sorted(s.get("classes", []), key=lambda c: c["d_hi"])
    t = a = 0.0
    diffs = []
    for c in cls[:-1]:
        t += c["target_fraction"]
        a += c["achieved_fraction"]
        diffs.append(100.0 * (a - t))
    if not diffs:
        return 0.0, 0.0
    return max(abs(x) for x in diffs), math.sqrt(sum(x * x for x in diffs) / len(diffs))


def study_grains(r, out, seeds):
    # the true A16 sizes above d_min = 1 mm at φ_M 0.40 in walled cubes of growing edge:
    # N grows as the volume (~300 grains at 20 mm, ~1.5e5 at 150 mm)
    base = load("a16-dmin.json")
    for edge in (20, 30, 45, 70, 100, 150):
        for seed in range(1, seeds + 1):
            job = json.loads(json.dumps(base))
            inp = job["inputs"]
            inp.update({"d_min": 1.0, "seed": seed, "algorithm": "rsa"})
            inp["domain"]["box"]["size"] = [edge, edge, edge]
            inp["phi"] = {"value": 0.40, "refers_to": "mix"}
            s, cpu, _ = r.run(job)
            if s is None:
                continue
            emax, el2 = sieve_errors(s)
            out.line("grains", grading="a16", edge=edge, seed=seed, **pack_fields(s), sieve_max_pp=emax,
                     sieve_l2_pp=el2, classes=len(s.get("classes", [])), cpu_s=cpu)


# ---- RVE size vs the spread of the homogenized stress, per boundary condition -------------
def homog_job(rve, bc, **extra):
    job = load("homog-2d.json")
    job["inputs"]["rve"] = {"file": rve}
    job["inputs"]["boundary_condition"] = bc
    for k, v in extra.items():
        job["inputs"][k] = v
    return job


def study_stress(r, out, seeds):
    rve_base = load("rve-2d.json")
    for n in (50, 150, 500, 1500):
        for seed in range(1, seeds + 1):
            job = json.loads(json.dumps(rve_base))
            job["inputs"]["count"] = n
            job["inputs"]["seed"] = seed
            rve = os.path.join(r.tmp, "rve_%d_%d.h5" % (n, seed))
            s, cpu_pack, _ = r.run(job, keep=rve)
            if s is None:
                continue
            for bc in ("taylor", "restricted_taylor", "periodic"):
                h, cpu, _ = r.run(homog_job(rve, bc))
                if h is None:
                    continue
                P = h.get("P", [math.nan] * 4)
                out.line("stress", bc=bc, n=n, seed=seed, P11=P[0], P22=P[3], P12=P[1],
                         contacts=h.get("contacts", 0), complete=bool(h.get("complete")),
                         reason=h.get("termination_reason", "?"), pack_cpu_s=cpu_pack,
                         cpu_s=cpu)
            os.unlink(rve)


# ---- cut-off d_min vs grain count, φ_eff and time (Titscher Figs. 3 and 10) -----------------
def study_dmin(r, out, seeds):
    base = load("a16-dmin.json")
    for dmin in (0.5, 1.0, 2.0, 4.0):
        for alg in ("rsa", "edmd"):
            for seed in range(1, seeds + 1):
                job = json.loads(json.dumps(base))
                inp = job["inputs"]
                inp.update({"d_min": dmin, "algorithm": alg, "seed": seed})
                s, cpu, _ = r.run(job)
                if s is None:
                    continue
                out.line("dmin", grading="a16", d_min=dmin, alg=alg, seed=seed, **pack_fields(s),
                         cut=s.get("mass_cut_fraction", 0.0), cpu_s=cpu)
        # Fig. 10/11: the largest Δd the shell reaches at this d_min (EDMD, maximize delta_d,
        # stopped at reduced pressure 10^6; below d_min 2 one run costs minutes: left out)
        if dmin < 2.0:
            continue
        for seed in range(1, seeds + 1):
            job = json.loads(json.dumps(base))
            inp = job["inputs"]
            inp.update({"d_min": dmin, "algorithm": "edmd", "seed": seed, "delta_d": dmin / 2})
            inp["edmd"] = {"growth": "shell", "maximize": "delta_d", "wall_gap": "none",
                           "jamming": {"reduced_pressure": 1e6}}
            s, cpu, _ = r.run(job)
            if s is None:
                continue
            out.line("dmin", grading="a16", d_min=dmin, alg="edmd_maxgap", seed=seed, **pack_fields(s),
                     cut=s.get("mass_cut_fraction", 0.0), delta_d_reached=s.get("edmd", {}).get("delta_d_reached", 0.0),
                     cpu_s=cpu)


# ---- relaxation tolerance and solver vs stress error and time -----------------------------
def p_steps(obs):
    keys = ["homogenize/P/11", "homogenize/P/12", "homogenize/P/21", "homogenize/P/22"]
    cols = [obs[k] for k in keys]
    return [list(x) for x in zip(*cols)]


def rel_err(P, R):
    num = max(math.sqrt(sum((a - b) ** 2 for a, b in zip(p, q))) for p, q in zip(P, R))
    den = max(math.sqrt(sum(b * b for b in q)) for q in R)
    return num / den if den > 0 else 0.0


def make_rve(r, n, seed):
    job = load("rve-2d.json")
    job["inputs"]["count"] = n
    job["inputs"]["seed"] = seed
    rve = os.path.join(r.tmp, "rve_%d_%d.h5" % (n, seed))
    s, _, _ = r.run(job, keep=rve)
    return rve if s is not None else None


RELAX_N = 1500


def study_relax(r, out, seeds):
    for seed in range(1, seeds + 1):
        rve = make_rve(r, RELAX_N, seed)
        if rve is None:
            continue
        # references: each solver at tol 1e-12 (err: the tolerance's error), and Newton's
        # (err_newton: near jamming DR and Newton may settle in different equilibria)
        refs = {}
        for solver in ("dr", "newton"):
            ref, _, ref_obs = r.run(homog_job(rve, "periodic", relaxation={"solver": solver, "tol": 1e-12}),
                                    full=True)
            if ref is not None:
                refs[solver] = p_steps(ref_obs)
        if len(refs) < 2:
            continue
        for solver in ("dr", "newton"):
            for tol in (1e-3, 1e-4, 1e-6, 1e-8, 1e-10):
                h, cpu, obs = r.run(homog_job(rve, "periodic", relaxation={"solver": solver, "tol": tol}), full=True)
                if h is None:
                    continue
                P = p_steps(obs)
                out.line("relax", solver=solver, tol=tol, n=RELAX_N, seed=seed, err=rel_err(P, refs[solver]),
                         err_newton=rel_err(P, refs["newton"]),
                         complete=bool(h.get("complete")), dr_iterations=h.get("dr_iterations_total", 0), cpu_s=cpu)
        os.unlink(rve)


# ---- analytic tangent vs central differences ----------------------------------------------
def study_tangent(r, out, seeds):
    F0 = [0.99, 0.0, 0.0, 1.0]  # 1 % uniaxial compression of the inflated RVE
    for seed in range(1, seeds + 1):
        rve = make_rve(r, RELAX_N, seed)
        if rve is None:
            continue
        relax = {"solver": "newton", "tol": 1e-12}
        a, cpu_a, obs_a = r.run(homog_job(rve, "periodic", load={"type": "list", "F": [F0]}, tangent=True,
                                          relaxation=relax), full=True)
        base, cpu_base, _ = r.run(homog_job(rve, "periodic", load={"type": "list", "F": [F0]}, relaxation=relax))
        if a is None or base is None:
            continue
        A = a["tangent"]
        t_an = obs_a["homogenize/tangent/seconds"]
        t_an = t_an[-1] if isinstance(t_an, list) else t_an
        for h in (1e-3, 1e-4, 1e-5, 1e-6):
            path = [F0]
            for kl in range(4):
                for sgn in (1, -1):
                    F = list(F0)
                    F[kl] += sgn * h
                    path.append(F)
            fd, cpu_fd, obs = r.run(homog_job(rve, "periodic", load={"type": "list", "F": path}, relaxation=relax),
                                    full=True)
            if fd is None:
                continue
            P = p_steps(obs)
            # column kl of A (row-major ij,kl as the summary prints it): dP_ij/dF_kl
            Afd = [0.0] * 16
            for kl in range(4):
                pp, pm = P[1 + 2 * kl], P[2 + 2 * kl]
                for ij in range(4):
                    Afd[4 * ij + kl] = (pp[ij] - pm[ij]) / (2 * h)
            num = math.sqrt(sum((x - y) ** 2 for x, y in zip(A, Afd)))
            den = math.sqrt(sum(x * x for x in A))
            # analytic_s: the tangent's own clock (the CPU difference of two runs is below the noise);
            # fd_cpu_s: the 8 perturbed relaxations, warm-started from the base state
            out.line("tangent", n=RELAX_N, seed=seed, h=h, rel_diff=num / den, analytic_s=t_an,
                     fd_cpu_s=cpu_fd - cpu_base, base_cpu_s=cpu_base)
        os.unlink(rve)


# ---- tet filling: size ratio R and ε vs φ, coordination and time ---------------------------
def study_tetfill(r, out, seeds):
    base = load("tetfill-box.json")
    for ratio in (1.5, 2, 3, 5, 7):
        for eps in (1e-4, 1e-2):
            for seed in range(1, seeds + 1):
                job = json.loads(json.dumps(base))
                inp = job["inputs"]
                # r̄ = 1 mm for every R (Jerier's size rule r_min = 2r̄/(R+1))
                rmin = 2.0 / (ratio + 1)
                inp["tetfill"] = {"r_min": rmin, "r_max": 2.0 - rmin, "epsilon": eps}
                inp["seed"] = seed
                s, cpu, _ = r.run(job)
                if s is None:
                    continue
                t = s.get("tetfill", {})
                out.line("tetfill", ratio=ratio, eps=eps, seed=seed, **pack_fields(s),
                         z=t.get("coordination_touching", 0.0),
                         z_tangent=t.get("coordination_tangent", 0.0), cpu_s=cpu)


STUDIES = {
    "algo": study_algo, "maxphi": study_maxphi, "growth": study_growth, "stops": study_stops,
    "grains": study_grains, "stress": study_stress, "dmin": study_dmin, "relax": study_relax,
    "tangent": study_tangent, "tetfill": study_tetfill,
}
SEEDS = {"algo": 2, "maxphi": 2, "growth": 2, "stops": 2, "grains": 5, "stress": 5, "dmin": 2, "relax": 2,
         "tangent": 2, "tetfill": 3}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--packd", default="build/packd")
    ap.add_argument("--data", default=None, help="write each study's lines to DATA/STUDY.txt")
    ap.add_argument("--seeds", type=int, default=0, help="seeds per case (default: per study)")
    ap.add_argument("studies", nargs="*")
    a = ap.parse_args()
    names = a.studies or list(STUDIES)
    for n in names:
        if n not in STUDIES:
            ap.error("unknown study %s (%s)" % (n, " ".join(STUDIES)))
    packd = os.path.abspath(a.packd)
    if a.data:
        os.makedirs(a.data, exist_ok=True)
    out = Out(a.data)
    with tempfile.TemporaryDirectory(prefix="tradeoff.") as tmp:
        r = Runner(packd, tmp)
        for n in names:
            t0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            runs = r.count
            STUDIES[n](r, out, a.seeds or SEEDS[n])
            t1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = t1.ru_utime - t0.ru_utime + t1.ru_stime - t0.ru_stime
            out.line("total", file=n, name=n, runs=r.count - runs, cpu_s=cpu)


if __name__ == "__main__":
    main()
