/* bench/homog — speed of the RVE homogenization (the bar: one periodic load
 * step of a 10⁴-grain 2D RVE relaxed to 1e-8 in < 2 s, tangent < 1 s).
 * Prints one line per case:
 *   bench=homog case=jam_2d rve=KIND n=N ... (making the RVE)
 *   bench=homog case=periodic_step_{dr,newton}_2d rve=KIND n=N iterations=K seconds=S ...
 *   bench=homog case=tangent_periodic_2d rve=KIND n=N tangent_s=S free_dofs=D
 *   bench=homog case=contact_eval_2d rve=KIND n=N pairs=P ns_per_pair=T ... (the
 *     forces-only pk_dem_eval a DR iteration runs, on the relaxed state)
 *   bench=homog case=contact_{eval,forces}_2d ... ns_per_pair=T threads=2
 *     serial_ns_per_pair=T1 speedup=T1/T (pk_dem_eval and pk_dem_eval_forces
 *     on a 2-thread core/base/par.h pool against the serial code, best of 9
 *     alternating rounds; the same bits; parallel_path=0: the list is
 *     below pk_dem_par_min_pairs, both serial)
 *   bench=homog case=periodic_step_newton_2d ... threads=2 seconds=S
 *     serial_seconds=S1 speedup=S1/S same_bits=B (the step again on a 2-thread
 *     pool, pk_homog_opts.par: the attempts speculative on the second thread,
 *     core/homog/homog_speculative.c; B = 1: the same end point, energy, P̄ and
 *     path statistics — on 0 the fields that differ go to stderr)
 * The step is 0.1 % uniaxial compression at tolerance 1e-8 (the thesis's),
 * solved by the Newton/DR/FIRE hybrid (core/homog/homog_newton.h, CHOLMOD) and by DR
 * alone from the same committed state; the DR line carries the agreement of
 * P̄ and of the energy (the same local minimum?) and the Newton line the
 * speed-up.  10⁴ grains with PACKD_BENCH_LARGE=1.
 * PACKD_BENCH_CASE=TEXT runs only the RVEs whose name KIND_N (dense_1000,
 * near_jamming_10000, …) contains TEXT; PACKD_BENCH_SEED=S makes the RVEs
 * from seed S (default 5) — more RVEs of the same kind.
 * PACKD_BENCH_RVE_CACHE=DIR keeps the relaxed RVEs in DIR/KIND_N_seedS.bin:
 * the RVE is relaxed at F̄ = 1 by the same hybrid the step measures, so
 * without the cache two builds of the solver compare different RVEs.  The
 * cache also freezes RVEs that today's code would build differently (any
 * change of the EDMD event order or of the relaxation moves them): figures
 * for a speed bar come from RVEs built by the commit measured (a fresh
 * DIR); a cache compares two builds on the same RVEs (docs/perf/homog.md). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/edmd/edmd.h"
#include "core/homog/homog_tangent.h"
#include "core/space/mat3.h"
#include "core/base/par.h"
#include "core/base/rng.h"
#include "api/solver/sparse_cholmod.h"

/* Case filter: PACKD_BENCH_CASE=TEXT keeps the RVEs whose name contains it. */
static int wanted(const char *name)
{
    const char *f = getenv("PACKD_BENCH_CASE");
    return !f || !*f || strstr(name, f) != NULL;
}

/* Seed of the RVEs (PACKD_BENCH_SEED, default 5). */
static uint64_t rve_seed(void)
{
    const char *e = getenv("PACKD_BENCH_SEED");
    return e && *e ? strtoull(e, NULL, 10) : 5;
}

/* Dynamic relaxation beside Newton: always at 1e3; at 1e4 it takes minutes
 * (λ_min estimate, see docs/homogenization.md), so only with
 * PACKD_BENCH_DR_LARGE=1. */
static int dr_wanted(size_t n)
{
    const char *e = getenv("PACKD_BENCH_DR_LARGE");
    return n <= 1000 || (e && *e == '1');
}

static pk_homog_opts opts(double tol)
{
    pk_homog_opts o = {.E_n = 1, .affine_predictor = 1};
    o.dr.tol = tol;
    o.dr.abs_floor = 0;
    o.dr.max_iter = 2000000;
    o.dr.lanczos_steps = 40;
    o.dr.refresh = 200;
    o.dr.skin = 0.3;
    return o;
}

/* A jammed periodic 2D RVE of n grains (radii 0.8–1.2), of two kinds:
 *  dense:  random overlapping disks at φ = 0.90 relaxed at F̄ = 1 — well
 *          above jamming (φ_J ≈ 0.84), a stiff, stable contact network;
 *  near_jamming: as packd makes one — EDMD grows hard disks until nearly
 *          jammed (reduced pressure 1e5), the radii are inflated by 1.5 %
 *          (the initial-state policy) and the overlaps relaxed at F̄ = 1.
 * Relaxation by Newton (DR when it stalls); time reported as 'jam'.  A tiled
 * small packing is no substitute: stable in its own cell, it is a saddle
 * for the long-wavelength modes of the big one. */
#define DENSE_PHI 0.90
static void build_rve(size_t n, int near_jamming, pk_homog_rve *rve, pk_homog_state *relaxed)
{
    pk_rng rng;
    pk_rng_seed(&rng, rve_seed(), 0);
    pk_particles p;
    pk_particles_init(&p, 2, n);
    double meas = 0;
    double *r = malloc(n * sizeof *r);
    for (size_t i = 0; i < n; i++) {
        r[i] = pk_rng_range(&rng, 0.8, 1.2);
        meas += M_PI * r[i] * r[i];
    }
    double L = sqrt(meas / (near_jamming ? 0.80 : DENSE_PHI));
    pk_box b = {.dim = 2, .L = {L, L, 0}, .periodic = {true, true, false}};
    for (size_t i = 0; i < n; i++) {
        double x[3] = {pk_rng_range(&rng, 0, L), pk_rng_range(&rng, 0, L), 0};
        pk_particles_push(&p, x, r[i], 0);
    }
    free(r);
    double tpack = 0, phi_pack = DENSE_PHI;
    if (near_jamming) {
        pk_edmd_params ep;
        pk_edmd_params_default(&ep);
        ep.start_zero = 1;
        ep.until = PK_EDMD_UNTIL_JAMMED;
        ep.p_max = 1e5;
        ep.seed = rve_seed();
        pk_edmd_stats es;
        double t0 = pk_wall_seconds();
        pk_edmd_run(&b, &p, &ep, NULL, &es);
        tpack = pk_wall_seconds() - t0;
        phi_pack = es.phi;
    }
    char err[128];
    pk_homog_rve_build(&b, &p, PK_BC_PERIODIC, near_jamming ? 1.015 : 1.0, rve, err, sizeof err);
    pk_homog_opts o = opts(1e-10);
    o.newton = &pk_sparse_cholmod;
    o.newton_max_iter = 200;
    pk_homog_state s0;
    pk_homog_state_init(rve, &o, &s0);
    double F[9];
    pk_m3_identity(F);
    pk_homog_step st;
    double t0 = pk_wall_seconds();
    pk_homog_eval(rve, &o, &s0, F, relaxed, &st, NULL);
    printf("bench=homog case=jam_2d rve=%s n=%zu phi_packed=%.4f edmd_seconds=%.3f "
           "factorisations=%zu qn_steps=%zu dr_iterations=%zu seconds=%.3f exit=%s stop=%s\n",
           near_jamming ? "near_jamming" : "dense", n, phi_pack, tpack, st.newton.iterations,
           st.newton.steps, st.dr.iterations, pk_wall_seconds() - t0,
           pk_newton_exit_name(st.newton.exit), pk_dr_stop_name(st.dr.stop));
    pk_homog_state_free(&s0);
    pk_particles_free(&p);
}

/* The RVE cache (PACKD_BENCH_RVE_CACHE=DIR): the RVE and its relaxed state
 * at F̄ = 1 (frictionless: no rotations, no slip history) in
 * DIR/KIND_N_seedS.bin — a header, then the arrays.  A file whose header or
 * size does not match is rebuilt. */
#define CACHE_MAGIC "PKRVE01"
typedef struct rve_cache_head {
    char magic[8];
    uint64_t n, ncontact, seed;
    int32_t near_jamming, dim, bc, periodic;
    double L[3], V, F[9];
} rve_cache_head;

static size_t cache_body_bytes(size_t n, size_t ncontact)
{
    return n * (7 * sizeof(double) + 2 * sizeof(int32_t) + 2) + ncontact * sizeof(uint64_t);
}

static int cache_path(size_t n, int near_jamming, char *path, size_t len)
{
    const char *dir = getenv("PACKD_BENCH_RVE_CACHE");
    if (!dir || !*dir)
        return 0;
    snprintf(path, len, "%s/%s_%zu_seed%llu.bin", dir, near_jamming ? "near_jamming" : "dense", n,
             (unsigned long long)rve_seed());
    return 1;
}

/* fread/fwrite of count items, 0 when all went through */
static int io(FILE *fp, void *p, size_t size, size_t count, int write)
{
    if (!count)
        return 0;
    return (write ? fwrite(p, size, count, fp) : fread(p, size, count, fp)) != count;
}

static int cache_arrays(FILE *fp, pk_homog_rve *rve, pk_homog_state *s, int write)
{
    size_t n = rve->n;
    return io(fp, rve->X, sizeof *rve->X, 3 * n, write) | io(fp, rve->r, sizeof *rve->r, n, write) |
        io(fp, rve->grain, sizeof *rve->grain, n, write) |
        io(fp, rve->species, sizeof *rve->species, n, write) | io(fp, rve->fixed, 1, n, write) |
        io(fp, rve->hull, 1, n, write) | io(fp, s->x, sizeof *s->x, 3 * n, write) |
        io(fp, s->keys, sizeof *s->keys, s->ncontact, write);
}

static void cache_save(const char *path, int near_jamming, pk_homog_rve *rve, pk_homog_state *s)
{
    rve_cache_head h = {.magic = CACHE_MAGIC,
                        .n = rve->n,
                        .ncontact = s->ncontact,
                        .seed = rve_seed(),
                        .near_jamming = near_jamming,
                        .dim = rve->dim,
                        .bc = (int32_t)rve->bc,
                        .periodic = rve->periodic,
                        .V = rve->V};
    memcpy(h.L, rve->L, sizeof h.L);
    memcpy(h.F, s->F, sizeof h.F);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return;
    int bad = io(fp, &h, sizeof h, 1, 1) | cache_arrays(fp, rve, s, 1);
    if (fclose(fp) != 0 || bad)
        remove(path);
}

/* 1 when rve and s were loaded from path, 0 (nothing allocated) otherwise. */
static int cache_load(const char *path, size_t n, int near_jamming, pk_homog_rve *rve,
                      pk_homog_state *s)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return 0;
    rve_cache_head h;
    int ok = io(fp, &h, sizeof h, 1, 0) == 0 && memcmp(h.magic, CACHE_MAGIC, 8) == 0 && h.n == n &&
        h.seed == rve_seed() && h.near_jamming == near_jamming && h.ncontact <= 8 * n &&
        fseek(fp, 0, SEEK_END) == 0 &&
        (size_t)ftell(fp) == sizeof h + cache_body_bytes(n, h.ncontact) &&
        fseek(fp, (long)sizeof h, SEEK_SET) == 0;
    if (ok) {
        memset(rve, 0, sizeof *rve);
        memset(s, 0, sizeof *s);
        rve->dim = h.dim;
        rve->bc = (pk_homog_bc)h.bc;
        rve->n = n;
        rve->periodic = h.periodic;
        memcpy(rve->L, h.L, sizeof h.L);
        rve->V = h.V;
        rve->X = malloc(3 * n * sizeof *rve->X);
        rve->r = malloc(n * sizeof *rve->r);
        rve->grain = malloc(n * sizeof *rve->grain);
        rve->species = malloc(n * sizeof *rve->species);
        rve->fixed = malloc(n);
        rve->hull = malloc(n);
        s->n = n;
        s->ncontact = h.ncontact;
        memcpy(s->F, h.F, sizeof h.F);
        s->x = malloc(3 * n * sizeof *s->x);
        s->u = calloc(n, sizeof *s->u);
        s->keys = malloc((h.ncontact ? h.ncontact : 1) * sizeof *s->keys);
        ok = rve->X && rve->r && rve->grain && rve->species && rve->fixed && rve->hull && s->x &&
            s->u && s->keys && cache_arrays(fp, rve, s, 0) == 0;
        if (!ok) {
            pk_homog_rve_free(rve);
            pk_homog_state_free(s);
        }
    }
    fclose(fp);
    return ok;
}

/* The RVE of the case: from the cache when there is one, else built (and
 * cached when a cache directory is given). */
static void make_rve(size_t n, int near_jamming, pk_homog_rve *rve, pk_homog_state *relaxed)
{
    char path[512];
    int cached = cache_path(n, near_jamming, path, sizeof path);
    if (cached && cache_load(path, n, near_jamming, rve, relaxed)) {
        printf("bench=homog case=jam_2d rve=%s n=%zu cached=%s contacts=%zu\n",
               near_jamming ? "near_jamming" : "dense", n, path, relaxed->ncontact);
        return;
    }
    build_rve(n, near_jamming, rve, relaxed);
    if (cached)
        cache_save(path, near_jamming, rve, relaxed);
}

/* ns per candidate of reps evaluations of c at s (forces only; keep: the
 * pair arrays stored, pk_dem_eval, else pk_dem_eval_forces). */
static double eval_ns(pk_dem_pairs *c, const pk_dem_geom *g, const pk_homog_rve *rve,
                      const pk_homog_state *s, double *f, size_t reps, int keep)
{
    double t0 = pk_wall_seconds();
    for (size_t k = 0; k < reps; k++) {
        if (keep)
            pk_dem_eval(c, g, s->x, rve->r, rve->n, 1.0, f, NULL, NULL);
        else
            pk_dem_eval_forces(c, g, s->x, rve->r, rve->n, 1.0, f);
    }
    return 1e9 * (pk_wall_seconds() - t0) / ((double)reps * (double)c->n);
}

/* The evaluation on 2 threads (core/base/par.h pool in c->par) against the
 * serial one, best of ROUNDS alternating rounds each (the machine is
 * shared: ±20 % between single runs), for pk_dem_eval (case
 * contact_eval_2d, the line above's function) and pk_dem_eval_forces (case
 * contact_forces_2d, the DR/FIRE iterations' one); speedup = serial/2
 * threads.  The results are bit-identical (tests/unit/test_dem_parallel.c). */
#define ROUNDS 9
static void parallel_eval_cases(pk_dem_pairs *c, const pk_dem_geom *g, const pk_homog_rve *rve,
                                const pk_homog_state *s, double *f, const char *kind)
{
    pk_par *par = pk_par_new(2);
    if (!par)
        return;
    size_t reps = 1 + 10000000 / c->n;
    for (int keep = 1; keep >= 0; keep--) {
        double ser = INFINITY, two = INFINITY;
        for (int k = 0; k < ROUNDS; k++) {
            c->par = NULL;
            ser = fmin(ser, eval_ns(c, g, rve, s, f, reps, keep));
            c->par = par;
            two = fmin(two, eval_ns(c, g, rve, s, f, reps, keep));
        }
        /* the same bits (checked in tests/unit/test_dem_parallel.c; here on
         * the bench's RVE too) */
        double *f2 = malloc(3 * rve->n * sizeof *f2);
        int same = 0;
        if (f2) {
            eval_ns(c, g, rve, s, f2, 1, keep); /* on the pool */
            c->par = NULL;
            eval_ns(c, g, rve, s, f, 1, keep);
            same = memcmp(f, f2, 3 * rve->n * sizeof *f) == 0;
            free(f2);
        }
        c->par = NULL;
        printf("bench=homog case=%s rve=%s n=%zu pairs=%zu reps=%zu rounds=%d "
               "ns_per_pair=%.2f threads=2 serial_ns_per_pair=%.2f speedup=%.2f same_bits=%d "
               "parallel_path=%d\n",
               keep ? "contact_eval_2d" : "contact_forces_2d", kind, rve->n, c->n, reps, ROUNDS,
               two, ser, ser / two, same, c->n >= pk_dem_par_min_pairs);
    }
    pk_par_free(par);
}

/* Time of the contact evaluation a DR iteration runs (forces only) per
 * candidate pair, on the relaxed RVE under the step's F̄; the repetitions
 * make ~10⁷ pair evaluations (≈ 0.1 s). */
static void eval_case(const pk_homog_rve *rve, const pk_homog_state *s, const double F[9],
                      double skin, const char *kind)
{
    pk_dem_geom g = {.dim = rve->dim, .periodic = rve->periodic};
    memcpy(g.L, rve->L, sizeof g.L);
    pk_dem_geom_set_F(&g, F);
    pk_dem_pairs c = {0};
    double *f = malloc(3 * rve->n * sizeof *f);
    if (!f || pk_dem_pairs_build(&c, &g, s->x, rve->r, rve->n, skin) != 0 || c.n == 0) {
        free(f);
        pk_dem_pairs_free(&c);
        return;
    }
    size_t reps = 1 + 10000000 / c.n, nc = 0;
    double t0 = pk_wall_seconds();
    for (size_t k = 0; k < reps; k++)
        nc = pk_dem_eval(&c, &g, s->x, rve->r, rve->n, 1.0, f, NULL, NULL);
    double t = pk_wall_seconds() - t0;
    printf("bench=homog case=contact_eval_2d rve=%s n=%zu pairs=%zu contacts=%zu reps=%zu "
           "ns_per_pair=%.2f threads=1\n",
           kind, rve->n, c.n, nc, reps, 1e9 * t / ((double)reps * (double)c.n));
    parallel_eval_cases(&c, &g, rve, s, f, kind);
    free(f);
    pk_dem_pairs_free(&c);
}

/* The Newton/DR/FIRE step again with a 2-thread pool (pk_homog_opts.par):
 * its time against the serial one (tnw, measured just before) and whether
 * the step gives the same bits (energy, P̄, iterations). */
static void step_threads_case(const pk_homog_rve *rve, const pk_homog_opts *on,
                              const pk_homog_state *s0, const double F[9], const pk_homog_state *tn,
                              const pk_homog_step *sn, double tnw, const char *kind)
{
    pk_homog_opts op = *on;
    op.par = pk_par_new(2);
    if (!op.par)
        return;
    pk_homog_state tp = {0};
    pk_homog_step sp;
    double t0 = pk_wall_seconds();
    pk_homog_eval(rve, &op, s0, F, &tp, &sp, NULL);
    double t = pk_wall_seconds() - t0;
    /* the same step: end point, stress, energy and the path's statistics */
    int same = memcmp(&sp.energy, &sn->energy, sizeof sp.energy) == 0 &&
        memcmp(sp.P, sn->P, sizeof sp.P) == 0 &&
        memcmp(tp.x, tn->x, 3 * rve->n * sizeof *tp.x) == 0 &&
        sp.dr.iterations == sn->dr.iterations && sp.dr.rebuilds == sn->dr.rebuilds &&
        sp.dr.stop == sn->dr.stop && sp.newton.iterations == sn->newton.iterations &&
        sp.newton.steps == sn->newton.steps && sp.newton.attempts == sn->newton.attempts &&
        sp.newton.fire_iterations == sn->newton.fire_iterations &&
        sp.newton.exit == sn->newton.exit;
    if (!same)
        fprintf(stderr,
                "DIFF energy %d P %d x %d it %zu/%zu reb %zu/%zu stop %d/%d fac %zu/%zu steps "
                "%zu/%zu att %zu/%zu fire %zu/%zu exit %d/%d\n",
                memcmp(&sp.energy, &sn->energy, sizeof sp.energy) == 0,
                memcmp(sp.P, sn->P, sizeof sp.P) == 0,
                memcmp(tp.x, tn->x, 3 * rve->n * sizeof *tp.x) == 0, sp.dr.iterations,
                sn->dr.iterations, sp.dr.rebuilds, sn->dr.rebuilds, sp.dr.stop, sn->dr.stop,
                sp.newton.iterations, sn->newton.iterations, sp.newton.steps, sn->newton.steps,
                sp.newton.attempts, sn->newton.attempts, sp.newton.fire_iterations,
                sn->newton.fire_iterations, sp.newton.exit, sn->newton.exit);
    printf("bench=homog case=periodic_step_newton_2d rve=%s n=%zu threads=2 seconds=%.3f "
           "serial_seconds=%.3f speedup=%.2f same_bits=%d\n",
           kind, rve->n, t, tnw, tnw / t, same);
    pk_homog_state_free(&tp);
    pk_par_free(op.par);
}

/* max |P̄_a − P̄_b| / max |P̄_a| */
static double P_rel_diff(const pk_homog_step *a, const pk_homog_step *b)
{
    double d = 0, Pn = 0;
    for (int c = 0; c < 9; c++) {
        Pn = fmax(Pn, fabs(a->P[c]));
        d = fmax(d, fabs(a->P[c] - b->P[c]));
    }
    return d / Pn;
}

static double step_case(size_t n, int near_jamming)
{
    char name[64];
    snprintf(name, sizeof name, "%s_%zu", near_jamming ? "near_jamming" : "dense", n);
    if (!wanted(name))
        return 0;
    pk_homog_rve rve;
    pk_homog_state s0 = {0}, td = {0}, tn = {0};
    make_rve(n, near_jamming, &rve, &s0);
    const char *kind = near_jamming ? "near_jamming" : "dense";
    pk_homog_opts o = opts(1e-8);
    double F[9];
    pk_m3_identity(F);
    F[0] = 0.999;
    eval_case(&rve, &s0, F, o.dr.skin, kind);
    pk_homog_step sd, sn;
    pk_homog_opts on = o;
    on.newton = &pk_sparse_cholmod;
    on.newton_max_iter = 50;
    double t0 = pk_wall_seconds();
    clock_t c0 = clock(); /* CPU time: on the shared machine wall time measures the load */
    pk_homog_eval(&rve, &on, &s0, F, &tn, &sn, NULL);
    double cnw = (double)(clock() - c0) / CLOCKS_PER_SEC;
    double tnw = pk_wall_seconds() - t0;
    double tdr = -1, rate = 0;
    if (dr_wanted(n)) {
        t0 = pk_wall_seconds();
        pk_homog_eval(&rve, &o, &s0, F, &td, &sd, NULL);
        tdr = pk_wall_seconds() - t0;
        rate = (double)n * (double)sd.dr.iterations / tdr;
        printf("bench=homog case=periodic_step_dr_2d rve=%s n=%zu iterations=%zu seconds=%.3f "
               "particle_iter_per_s=%.3g stop=%s contacts=%zu rattlers=%zu energy=%.12g "
               "P_rel_diff_newton_vs_dr=%.2g energy_rel_diff_newton_vs_dr=%.2g\n",
               kind, n, sd.dr.iterations, tdr, rate, pk_dr_stop_name(sd.dr.stop), sd.contacts,
               sd.rattlers, sd.energy, P_rel_diff(&sd, &sn), (sn.energy - sd.energy) / sd.energy);
        /* DR without its increments' λ_min (pk_dr_params.plain_lambda_min): the
         * iterations and time that estimate saves, and where each ends */
        pk_homog_opts op = o;
        op.dr.plain_lambda_min = 1;
        pk_homog_state tp = {0};
        pk_homog_step sp;
        t0 = pk_wall_seconds();
        pk_homog_eval(&rve, &op, &s0, F, &tp, &sp, NULL);
        double tpl = pk_wall_seconds() - t0;
        printf(
            "bench=homog case=periodic_step_dr_plain_2d rve=%s n=%zu iterations=%zu seconds=%.3f "
            "stop=%s energy=%.12g P_rel_diff_vs_increments=%.2g speedup_of_increments=%.2f\n",
            kind, n, sp.dr.iterations, tpl, pk_dr_stop_name(sp.dr.stop), sp.energy,
            P_rel_diff(&sd, &sp), tpl / tdr);
        pk_homog_state_free(&tp);
    }
    printf("bench=homog case=periodic_step_newton_2d rve=%s n=%zu factorisations=%zu qn_steps=%zu "
           "dr_iterations=%zu fire_iterations=%zu attempts=%zu shift_raises=%zu seconds=%.3f "
           "cpu_s=%.3f "
           "exit=%s stop=%s residual_rel=%.2g "
           "contacts=%zu rattlers=%zu energy=%.17g P11=%.17g P22=%.17g speedup_vs_dr=%.2f\n",
           kind, n, sn.newton.iterations, sn.newton.steps,
           sn.dr.iterations - sn.newton.fire_iterations, sn.newton.fire_iterations,
           sn.newton.attempts, sn.newton.shifts, tnw, cnw, pk_newton_exit_name(sn.newton.exit),
           pk_dr_stop_name(sn.dr.stop), sn.dr.f / sn.dr.f0, sn.contacts, sn.rattlers, sn.energy,
           sn.P[0], sn.P[4], tdr > 0 ? tdr / tnw : -1);
    step_threads_case(&rve, &on, &s0, F, &tn, &sn, tnw, kind);
    double A[81];
    pk_tangent_info ti;
    int rc = pk_homog_tangent(&rve, &o, &tn, &pk_sparse_cholmod, A, &ti);
    printf("bench=homog case=tangent_periodic_2d rve=%s n=%zu tangent_s=%.3f free_dofs=%zu "
           "status=%s rc=%d "
           "A1111=%.4g\n",
           kind, n, ti.seconds, ti.free_dofs, pk_sparse_status_name(ti.block.status), rc, A[0]);
    pk_homog_state_free(&s0);
    pk_homog_state_free(&td);
    pk_homog_state_free(&tn);
    pk_homog_rve_free(&rve);
    return rate;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* one line per case, as it comes */
    step_case(1000, 0);
    step_case(1000, 1);
    const char *large = getenv("PACKD_BENCH_LARGE");
    if (large && *large == '1') {
        step_case(10000, 0);
        step_case(10000, 1);
    }
    return 0;
}
