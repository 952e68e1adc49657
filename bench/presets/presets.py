#!/usr/bin/env python3
"""bench/presets/presets.py — the measurements behind the quality presets and
the automatic algorithm choice (docs/presets.md).  Each case runs small jobs
through `packd run` over several seeds and prints one machine-readable line
per run:
  bench=presets case=NAME knob=VALUE seed=S cpu_s=T metric=X [file_bytes=B]
then one summary line per knob value: mean cost and the mean |error| against
the reference (the finest value of the sweep).
Usage: PACKD=build/packd python3 bench/presets/presets.py [case ...]
Cases: edmd_gamma edmd_pmax rsa_nf rsa_reach auto homog_tol homog_outputs pack_outputs
       presets (preset_homog alone: its homogenize part)"""
import atexit, json, os, resource, shutil, statistics, subprocess, sys, tempfile

PACKD = os.environ.get("PACKD", "build/packd")
SEEDS = [1, 2, 3]
TMP = tempfile.mkdtemp(prefix="presets-bench-")
atexit.register(shutil.rmtree, TMP, True)


def run(job, name):
    """Run one job; (summary, CPU seconds of the child, file size)."""
    path = os.path.join(TMP, name + ".json")
    out = os.path.join(TMP, name + ".h5")
    with open(path, "w") as f:
        json.dump(job, f)
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([PACKD, "run", path, "-o", out, "--json"], capture_output=True, text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode not in (0, 3):
        sys.exit(f"{name}: packd run failed ({p.returncode}): {p.stderr}")
    return json.loads(p.stdout), cpu, os.path.getsize(out), out


def line(**kv):
    print("bench=presets " + " ".join(f"{k}={v}" for k, v in kv.items()), flush=True)


def sweep(case, values, make_job, metric, ref_value):
    """Every value × seed; then the mean cost and mean |metric − reference|."""
    rows = {}
    for v in values:
        for s in SEEDS:
            summ, cpu, size, _ = run(make_job(v, s), f"{case}-{v}-{s}")
            m = metric(summ)
            rows.setdefault(v, []).append((s, cpu, m))
            extra = {"dr_iterations": summ["dr_iterations_total"]} if "dr_iterations_total" in summ else {}
            line(case=case, knob=v, seed=s, cpu_s=f"{cpu:.3f}", metric=f"{m:.10g}", file_bytes=size,
                 **extra)
    ref = {s: m for s, _, m in rows[ref_value]}
    for v in values:
        errs = [abs(m - ref[s]) for s, _, m in rows[v]]
        rel = [abs(m - ref[s]) / abs(ref[s]) if ref[s] else 0 for s, _, m in rows[v]]
        line(case=case + "_summary", knob=v,
             cpu_s_median=f"{statistics.median(c for _, c, _ in rows[v]):.3f}",
             metric_mean=f"{statistics.mean(m for _, _, m in rows[v]):.8g}",
             abs_err_mean=f"{statistics.mean(errs):.3g}", abs_err_max=f"{max(errs):.3g}",
             rel_err_max=f"{max(rel):.3g}")
    return rows


def mono3d(seed, n=300, edmd=None, phi=0.3, alg="edmd"):
    job = {"process": "pack", "inputs": {
        "dim": 3, "domain": {"box": {"size": [10, 10, 10], "periodic": True}},
        "grading": {"type": "classes", "classes": [{"d": 1, "volume_percent": 100}]},
        "count": n, "phi": {"value": phi, "refers_to": "resolved"},
        "algorithm": alg, "seed": seed}}
    if edmd is not None:
        job["inputs"]["edmd"] = edmd
    return job


def edmd_gamma():
    sweep("edmd_gamma", [0.1, 0.03, 0.01, 0.003],
          lambda g, s: mono3d(s, edmd={"until": "jammed", "growth_rate": g}),
          lambda r: r["phi_resolved"], 0.003)


def edmd_pmax():
    sweep("edmd_pmax", [1e3, 1e4, 1e6, 1e9, 1e12],
          lambda p, s: mono3d(s, edmd={"until": "jammed", "jamming": {"reduced_pressure": p}}),
          lambda r: r["phi_resolved"], 1e12)


def rsa_nf():
    # equal spheres asked beyond RSA's saturation (0.384): N^F sets where it gives up
    sweep("rsa_nf", [100, 1000, 10000, 100000, 1000000, 10000000],
          lambda nf, s: {"process": "pack", "inputs": dict(
              mono3d(s, n=3000, phi=0.45, alg="rsa")["inputs"], rsa={"max_failed_draws": nf})},
          lambda r: r["phi_resolved"], 10000000)


GRADINGS = {  # name: (dim, grading, d_min, box edge)
    "mono3d": (3, {"type": "classes", "classes": [{"d": 4, "volume_percent": 100}]}, None, 40),
    "two3d": (3, {"type": "classes", "classes": [{"d": 4, "volume_percent": 50},
                                                 {"d": 2, "volume_percent": 50}]}, None, 40),
    "a16_d4": (3, {"type": "preset", "name": "A16"}, 4, 100),
    "a16_d2": (3, {"type": "preset", "name": "A16"}, 2, 60),
    "fuller_d2": (3, {"type": "fuller", "q": 0.5, "d_max": 16}, 2, 60),
    "mono2d": (2, {"type": "classes", "classes": [{"d": 1, "volume_percent": 100}]}, None, 40),
    "quartz2d": (2, {"type": "classes", "classes": [
        {"d": 0.25, "volume_percent": 2.5}, {"d": 0.16, "volume_percent": 39.72},
        {"d": 0.125, "volume_percent": 44.22}, {"d": 0.1, "volume_percent": 9.58},
        {"d": 0.063, "volume_percent": 3.70}, {"d": 0.05, "volume_percent": 0.28}]}, None, 6),
}


def graded(name, seed, phi, alg, extra=None):
    dim, g, dmin, L = GRADINGS[name]
    inp = {"dim": dim, "domain": {"box": {"size": [L] * dim, "periodic": True}}, "grading": g,
           "phi": {"value": phi, "refers_to": "resolved"}, "algorithm": alg, "seed": seed}
    if dmin:
        inp["d_min"] = dmin
    if name == "quartz2d":
        inp["sampling"] = "continuous"
    if extra:
        inp.update(extra)
    return {"process": "pack", "inputs": inp}


def rsa_reach():
    """How far RSA gets per grading: each target φ_eff (0.02 apart) over the
    seeds, complete or not (N^F = 10^6, open draws); the reach is the largest
    target every seed completes.  With the size spread d_max/d_min: the rule of
    the automatic choice."""
    start = {"mono3d": 0.34, "two3d": 0.40, "a16_d4": 0.48, "a16_d2": 0.52, "fuller_d2": 0.52,
             "mono2d": 0.50, "quartz2d": 0.58}
    top = 0.7  # RSA takes over 10 s per 3500 grains beyond: far past the break-even
    targets = {k: [round(v + 0.02 * j, 2) for j in range(int((top - v) / 0.02 + 1e-9) + 1)]
               for k, v in start.items()
               if not os.environ.get("REACH_GRADINGS") or k in os.environ["REACH_GRADINGS"]}
    for name, phis in targets.items():
        for phi in phis:
            done = []
            for s in SEEDS:
                summ, cpu, _, _ = run(graded(name, s, phi, "rsa"), f"reach-{name}-{phi}-{s}")
                cls = summ["classes"]
                spread = max(c["d_hi"] for c in cls) / min(c["d_lo"] for c in cls)
                done.append(bool(summ["complete"]))
                line(case="rsa_reach", grading=name, phi_target=phi, seed=s, cpu_s=f"{cpu:.3f}",
                     phi=f"{summ['phi_resolved']:.5f}", spread=f"{spread:.3g}",
                     placed=summ["count_placed"], complete=str(summ["complete"]).lower())
            line(case="rsa_reach_summary", grading=name, phi_target=phi,
                 complete=f"{sum(done)}/{len(done)}")
            if not any(done):
                break


def auto():
    """Time to a target φ_eff: RSA against EDMD (RSA start, relative growth)."""
    cases = {"a16_d4": [0.45, 0.5, 0.55, 0.6], "mono3d": [0.3, 0.35, 0.38],
             "a16_d2": [0.58, 0.62, 0.66], "fuller_d2": [0.58, 0.62, 0.66]}
    for name, phis in cases.items():
        if os.environ.get("AUTO_GRADINGS") and name not in os.environ["AUTO_GRADINGS"].split(","):
            continue
        for phi in phis:
            for alg in ("rsa", "edmd"):
                for s in SEEDS:
                    summ, cpu, _, _ = run(graded(name, s, phi, alg), f"auto-{name}-{phi}-{alg}-{s}")
                    line(case="auto", grading=name, phi_target=phi, algorithm=alg, seed=s,
                         cpu_s=f"{cpu:.3f}", phi=f"{summ['phi_resolved']:.5f}",
                         complete=str(summ["complete"]).lower())


def rve(seed, count=150):
    job = json.load(open(os.path.join(os.path.dirname(__file__), "../../examples/homogenize/rve-rsa-2d.json")))
    job["inputs"]["seed"] = seed
    if count != 150:  # the same RVE, larger: the box grows with the count
        edge = 20.0 * (count / 150) ** 0.5
        job["inputs"].update(count=count, domain={"box": {"size": [edge, edge], "periodic": True}})
    _, _, _, out = run(job, f"rve-{seed}-{count}")
    return out


def homog_job(rvefile, relax, extra=None):
    inp = {"rve": {"file": rvefile}, "boundary_condition": "periodic",
           "load": {"type": "uniaxial_compression", "axis": 1, "strain": 0.02, "steps": 20},
           "contact": {"E_n": 50}, "relaxation": relax,
           "initial_state": {"policy": "radius_inflation", "value": 0.3}}
    if extra:
        inp.update(extra)
    return {"process": "homogenize", "inputs": inp}


def sigma_norm(r):
    return sum(x * x for x in r["sigma"]) ** 0.5


def homog_tol():
    rves = {s: rve(s) for s in SEEDS}
    for solver in ("dr", "newton"):
        sweep("homog_tol_" + solver, [1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
              lambda t, s: homog_job(rves[s], {"tol": t, "solver": solver}), sigma_norm, 1e-12)


def homog_outputs():
    """What the optional outputs cost on a 2000-grain RVE: contacts, micro
    state, tangent (periodic), friction (taylor, its own boundary condition)."""
    rves = {s: rve(s, 2000) for s in SEEDS}
    variants = {"none": ("periodic", {}), "contacts": ("periodic", {"output": {"contacts": True}}),
                "micro_state": ("periodic", {"output": {"micro_state": True}}),
                "tangent": ("periodic", {"tangent": True}),
                "no_frames": ("periodic", {"output": {"frames": False}}),
                "taylor_none": ("taylor", {}),
                "taylor_friction": ("taylor", {"friction": {"rho_deg": 30}})}
    only = os.environ.get("OUTPUT_VARIANTS")
    for name, (bc, extra) in variants.items():
        if only and name not in only.split(","):
            continue
        for s in SEEDS:
            job = homog_job(rves[s], {"tol": 1e-8}, dict(extra, boundary_condition=bc))
            summ, cpu, size, _ = run(job, f"hout-{name}-{s}")
            line(case="homog_outputs", variant=name, seed=s, cpu_s=f"{cpu:.3f}", file_bytes=size,
                 model=json.dumps(summ["model"], separators=(",", ":")))


def pack_outputs():
    """2D against 3D at the same count (20 000 grains, RSA at φ 0.3)."""
    for dim in (2, 3):
        for s in SEEDS:
            job = {"process": "pack", "inputs": {
                "dim": dim, "domain": {"box": {"size": [100] * dim, "periodic": True}},
                "grading": {"type": "classes", "classes": [{"d": 1, "volume_percent": 100}]},
                "count": 20000, "phi": {"value": 0.3, "refers_to": "resolved"},
                "algorithm": "rsa", "seed": s}}
            _, cpu, size, _ = run(job, f"pout-{dim}-{s}")
            line(case="pack_outputs", dim=dim, seed=s, cpu_s=f"{cpu:.3f}", file_bytes=size)


QUALITIES = ["draft", "standard", "fine"]


def presets():
    """Each preset as a job sends it (only "quality" set): cost and error
    against the fine run of the same seed."""
    sweep("preset_edmd_jammed", QUALITIES,
          lambda q, s: dict(mono3d(s, edmd={"until": "jammed"}),
                            inputs=dict(mono3d(s, edmd={"until": "jammed"})["inputs"], quality=q)),
          lambda r: r["phi_resolved"], "fine")
    sweep("preset_rsa_saturation", QUALITIES,
          lambda q, s: dict(mono3d(s, n=3000, phi=0.45, alg="rsa"),
                            inputs=dict(mono3d(s, n=3000, phi=0.45, alg="rsa")["inputs"], quality=q)),
          lambda r: r["phi_resolved"], "fine")
    preset_homog()


def preset_homog():
    rves = {s: rve(s, 2000) for s in SEEDS}
    sweep("preset_homog", QUALITIES,
          lambda q, s: dict(homog_job(rves[s], {}), inputs=dict(homog_job(rves[s], {})["inputs"], quality=q)),
          sigma_norm, "fine")


CASES = {f.__name__: f for f in (edmd_gamma, edmd_pmax, rsa_nf, rsa_reach, auto, homog_tol,
                                 homog_outputs, pack_outputs, presets, preset_homog)}
for c in sys.argv[1:] or CASES:
    CASES[c]()
