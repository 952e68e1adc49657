/* bench/fe2 — speed of the FE² macro problem on the thesis's first example
 * (Meier 2009 §6.4.1: a 100 × 100 mm block in 3 × 3 Q1, 36 RVEs of 150
 * grains, E_n = 50; examples/fe2/block-*.json).  Prints one line per case:
 *   bench=fe2 case=gp_eval bc=BC grains=N gps=36 threads=2 evals_per_s=R
 *     serial_evals_per_s=R1 efficiency=R/(2·R1) cpu_evals_per_s=Rc cpu_ratio=C
 *     parallelism=Q rounds=K load=L
 *     (one evaluation round of every Gauss point — pk_fe2_residual, the trial
 *     evaluations plus f_int — at a fixed compressed state, alternating the
 *     serial and the 2-thread pool, medians of the wall times; efficiency is
 *     the parallel efficiency on 2 cores, the bar ≥ 0.85; cpu_evals_per_s the
 *     serial rate in CPU time (what one idle core gives); cpu_ratio the CPU
 *     time of a 2-thread round over a serial one: the work parallelism adds,
 *     which bounds the efficiency at 1/cpu_ratio on two idle cores;
 *     parallelism the CPU time over the wall time of a 2-thread round: below
 *     2 when the machine's other load took the second core)
 *   bench=fe2 case=example1 bc=BC p=0.2 threads=T steps=35 iterations=I
 *     corrections=C cuts=X seconds=S s_per_iteration=S/I cpu_seconds=U
 *     peak_rss_kb=M converged=0|1 (all load steps of example 1: 5 steps of
 *     side pressure, then the top pushed down 3 mm in 30; the bar for Taylor
 *     on 2 threads: under 120 s; s_per_iteration is the time per macro
 *     Newton iteration, one evaluation round and one factorisation)
 * load= is the 1-minute load average when the case started: the machine is
 * shared, and the figures are only comparable at a similar load.
 * PACKD_BENCH_CASE=TEXT runs only the cases whose name ("gp_eval_taylor",
 * "example1_taylor_t2", …) contains TEXT; PACKD_BENCH_SEED=S makes the RVE
 * from seed S (default 1); PACKD_BENCH_FE2_BCS=taylor,periodic picks the
 * boundary conditions (default all three for gp_eval, taylor for example1);
 * PACKD_BENCH_FE2_INFLATE=V the radius inflation of the RVE (default 0.001,
 * as in examples/fe2: an RVE just jammed has no stiffness under the relaxing
 * boundary conditions). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "api/solver/sparse_cholmod.h"
#include "core/base/par.h"
#include "core/base/rng.h"
#include "core/edmd/edmd.h"
#include "core/fe2/fe2_rve.h"
#include "core/homog/homog_rve.h"
#include "core/fe2/fe2_solver.h"

#define GRAINS 150
#define LX 100.0
#define NX 3
#define E_N 50.0

static int wanted(const char *name)
{
    const char *f = getenv("PACKD_BENCH_CASE");
    return !f || !*f || strstr(name, f) != NULL;
}

static int bc_wanted(const char *bc, int by_default)
{
    const char *f = getenv("PACKD_BENCH_FE2_BCS");
    if (!f || !*f)
        return by_default;
    size_t n = strlen(bc);
    for (const char *q = f; (q = strstr(q, bc)) != NULL; q += n)
        if ((q == f || q[-1] == ',') && (q[n] == 0 || q[n] == ','))
            return 1;
    return 0;
}

/* The RVE's initial state (the fe2 jobs' initial_state radius_inflation):
 * every radius × (1 + PACKD_BENCH_FE2_INFLATE), default 0.001. */
static double inflation(void)
{
    const char *e = getenv("PACKD_BENCH_FE2_INFLATE");
    return e && *e ? strtod(e, NULL) : 0.001;
}

static uint64_t seed(void)
{
    const char *e = getenv("PACKD_BENCH_SEED");
    return e && *e ? strtoull(e, NULL, 10) : 1;
}

static double wall(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double load1(void)
{
    double l = NAN;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &l) != 1)
            l = NAN;
        fclose(f);
    }
    return l;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The RVE of example 1: 150 grains of Table 5.1 (1/40/74/35 of d = 0.250/
 * 0.160/0.125/0.100 mm) in a periodic square at φ 0.80, grown by EDMD from
 * zero radii until jammed (examples/fe2: the nested pack job). */
static void make_packing(pk_box *b, pk_particles *p)
{
    static const double d[4] = {0.250, 0.160, 0.125, 0.100};
    static const int count[4] = {1, 40, 74, 35};
    double area = 0;
    for (int k = 0; k < 4; k++)
        area += count[k] * M_PI * d[k] * d[k] / 4;
    double L = sqrt(area / 0.80);
    *b = (pk_box){.dim = 2, .L = {L, L, 0}, .periodic = {true, true, false}};
    pk_particles_init(p, 2, GRAINS);
    double x[3] = {0, 0, 0};
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < count[k]; i++)
            pk_particles_push(p, x, d[k] / 2, k);
    pk_edmd_params ep;
    pk_edmd_params_default(&ep);
    ep.start_zero = 1;
    ep.until = PK_EDMD_UNTIL_JAMMED;
    ep.equal_masses = 1;
    ep.seed = seed();
    pk_edmd_stats es;
    double t0 = wall();
    pk_edmd_run(b, p, &ep, NULL, &es);
    printf("bench=fe2 case=rve grains=%d phi=%.4f edmd_seconds=%.2f\n", GRAINS, es.phi,
           wall() - t0);
}

/* Example 1's macro problem: rollers on the left (u_x) and bottom (u_y), the
 * top's u_y prescribed, the side pressure on the right edge. */
typedef struct block {
    pk_fe2_mesh mesh;
    int32_t *fix;
    size_t nfix;
    double *f_unit; /* nodal forces of p = 1 on the right edge */
} block;

static void block_init(block *k)
{
    pk_fe2_mesh_rectangle(LX, LX, NX, NX, &k->mesh);
    char err[128];
    if (pk_fe2_mesh_finish(&k->mesh, err, sizeof err) != 0) {
        fprintf(stderr, "bench/fe2: %s\n", err);
        exit(1);
    }
    size_t n1 = NX + 1, ndof = 2 * k->mesh.nnode;
    k->fix = malloc(3 * n1 * sizeof *k->fix);
    k->nfix = 0;
    for (size_t j = 0; j < n1; j++) /* left: u_x */
        k->fix[k->nfix++] = (int32_t)(2 * (j * n1));
    for (size_t i = 0; i < n1; i++) /* bottom: u_y */
        k->fix[k->nfix++] = (int32_t)(2 * i + 1);
    for (size_t i = 0; i < n1; i++) /* top: u_y (the last ones) */
        k->fix[k->nfix++] = (int32_t)(2 * (NX * n1 + i) + 1);
    k->f_unit = calloc(ndof, sizeof *k->f_unit);
    const double t[2] = {-1, 0}; /* p = 1 against the outward normal +x */
    for (size_t j = 0; j < NX; j++)
        pk_fe2_edge_traction(&k->mesh, (int32_t)(j * n1 + NX), (int32_t)((j + 1) * n1 + NX), t,
                             k->f_unit);
}

static void block_free(block *k)
{
    pk_fe2_mesh_free(&k->mesh);
    free(k->fix);
    free(k->f_unit);
}

static pk_homog_bc bc_of(const char *name)
{
    return !strcmp(name, "taylor")           ? PK_BC_TAYLOR
        : !strcmp(name, "restricted_taylor") ? PK_BC_RESTRICTED_TAYLOR
                                             : PK_BC_PERIODIC;
}

/* The RVE material of every Gauss point, with the fe2 job's defaults
 * (api/homog's relaxation options: DR to 1e-8 relative). */
typedef struct rve_mat {
    pk_homog_rve rve;
    pk_fe2_rve m;
    pk_fe2_material mat;
} rve_mat;

static int rve_mat_init(rve_mat *r, const pk_box *b, const pk_particles *p, const char *bc,
                        size_t ngp, char *err, size_t errlen)
{
    if (pk_homog_rve_build(b, p, bc_of(bc), 1.0 + inflation(), &r->rve, err, errlen) != 0)
        return -1;
    double rmean = 0;
    for (size_t i = 0; i < r->rve.n; i++)
        rmean += r->rve.r[i] / (double)r->rve.n;
    pk_homog_opts o = {.E_n = E_N};
    o.dr.tol = 1e-8;
    o.dr.abs_floor = 1e-13 * E_N * rmean * (double)r->rve.n;
    o.dr.max_iter = 1000000;
    o.dr.lanczos_steps = 40;
    o.dr.refresh = 200;
    o.dr.skin = 0.3 * rmean;
    if (pk_fe2_rve_init(&r->m, &r->rve, 1, &o, &pk_sparse_cholmod, ngp, NULL, err, errlen) != 0) {
        pk_homog_rve_free(&r->rve);
        return -1;
    }
    r->mat = pk_fe2_rve_material(&r->m);
    return 0;
}

static void rve_mat_free(rve_mat *r)
{
    pk_fe2_rve_free(&r->m);
    pk_homog_rve_free(&r->rve);
}

/* gp_eval: evaluation rounds at the affine state of 1 % vertical and 0.4 %
 * horizontal compression with a small shear, serial against 2 threads. */
static void case_gp_eval(const block *k, const pk_box *b, const pk_particles *p, const char *bc)
{
    char name[64];
    snprintf(name, sizeof name, "gp_eval_%s", bc);
    if (!wanted(name))
        return;
    double ld = load1();
    rve_mat rm;
    char err[160];
    if (rve_mat_init(&rm, b, p, bc, pk_fe2_gauss_count(&k->mesh), err, sizeof err)) {
        printf("bench=fe2 case=gp_eval bc=%s error=\"%s\"\n", bc, err);
        return;
    }
    pk_par *pool = pk_par_new(2);
    pk_fe2_problem pb = {.mesh = &k->mesh,
                         .mat = &rm.mat,
                         .nfix = k->nfix,
                         .fix_dof = k->fix,
                         .solver = &pk_sparse_cholmod};
    size_t ndof = 2 * k->mesh.nnode, ngp = pk_fe2_gauss_count(&k->mesh);
    double *u = malloc(ndof * sizeof *u), *R = malloc(ndof * sizeof *R);
    for (size_t a = 0; a < k->mesh.nnode; a++) {
        double x = k->mesh.xy[2 * a], y = k->mesh.xy[2 * a + 1];
        u[2 * a] = -0.004 * x + 0.002 * y;
        u[2 * a + 1] = -0.010 * y;
    }
    enum { ROUNDS = 9 };
    double t1[ROUNDS], t2[ROUNDS], c1[ROUNDS], c2[ROUNDS];
    int rc = 0;
    for (int r = 0; r < ROUNDS && !rc; r++) {
        for (int twice = 0; twice < 2; twice++) { /* serial, then the pool; the next round swaps */
            int par = (r + twice) % 2;
            pb.par = par ? pool : NULL;
            double t0 = wall(), q0 = cpu();
            rc |= pk_fe2_residual(&pb, u, NULL, R, NULL, err, sizeof err);
            (par ? t2 : t1)[r] = wall() - t0;
            (par ? c2 : c1)[r] = cpu() - q0;
        }
    }
    if (rc)
        printf("bench=fe2 case=gp_eval bc=%s error=\"%s\"\n", bc, err);
    else {
        double s1 = median(t1, ROUNDS), s2 = median(t2, ROUNDS);
        printf("bench=fe2 case=gp_eval bc=%s grains=%d gps=%zu threads=2 evals_per_s=%.1f "
               "serial_evals_per_s=%.1f efficiency=%.3f cpu_evals_per_s=%.1f cpu_ratio=%.3f "
               "parallelism=%.2f rounds=%d load=%.2f\n",
               bc, GRAINS, ngp, (double)ngp / s2, (double)ngp / s1, s1 / (2 * s2),
               (double)ngp / median(c1, ROUNDS), median(c2, ROUNDS) / median(c1, ROUNDS),
               median(c2, ROUNDS) / s2, ROUNDS, ld);
    }
    fflush(stdout);
    free(u);
    free(R);
    pk_par_free(pool);
    rve_mat_free(&rm);
}

/* example1: every load step of the block at p = 0.2 on `threads` threads. */
static void case_example1(const block *k, const pk_box *b, const pk_particles *p, const char *bc,
                          int threads)
{
    char name[64];
    snprintf(name, sizeof name, "example1_%s_t%d", bc, threads);
    if (!wanted(name))
        return;
    double ld = load1();
    const double pressure = 0.2, u_top = -3.0;
    enum { CONFINE = 5, COMPRESS = 30 };
    rve_mat rm;
    char err[160];
    double t0 = wall(), c0 = cpu();
    if (rve_mat_init(&rm, b, p, bc, pk_fe2_gauss_count(&k->mesh), err, sizeof err)) {
        printf("bench=fe2 case=example1 bc=%s error=\"%s\"\n", bc, err);
        return;
    }
    pk_par *pool = pk_par_new(threads);
    pk_fe2_problem pb = {.mesh = &k->mesh,
                         .mat = &rm.mat,
                         .nfix = k->nfix,
                         .fix_dof = k->fix,
                         .solver = &pk_sparse_cholmod,
                         .par = pool};
    pk_fe2_newton_opts o = {
        .rtol = 1e-10, .atol = 1e-12, .max_iter = 20, .line_search = 1, .max_cuts = 8};
    pk_fe2_state s;
    pk_fe2_state_init(&s, &k->mesh);
    size_t ndof = s.ndof, n1 = NX + 1;
    double *uD = calloc(k->nfix, sizeof *uD), *fext = calloc(ndof, sizeof *fext);
    pk_fe2_step_report *rep = malloc(sizeof *rep);
    long iterations = 0, corrections = 0, cuts = 0;
    int steps = 0, ok = 1;
    for (int st = 1; st <= CONFINE + COMPRESS && ok; st++) {
        double lp = st <= CONFINE ? (double)st / CONFINE : 1.0;
        double lu = st <= CONFINE ? 0.0 : (double)(st - CONFINE) / COMPRESS;
        for (size_t i = 0; i < ndof; i++)
            fext[i] = pressure * lp * k->f_unit[i];
        for (size_t i = 0; i < n1; i++)
            uD[k->nfix - n1 + i] = u_top * lu;
        int rc = pk_fe2_step(&pb, &o, &s, uD, fext, rep, NULL);
        for (size_t q = 0; q < rep->nparts && q < 32; q++) {
            iterations += rep->parts[q].n;
            corrections += rep->parts[q].n - 1;
        }
        cuts += rep->cuts;
        ok = rc == 0;
        steps += ok;
        if (!ok)
            fprintf(stderr, "bench/fe2: example1 %s step %d: %s\n", bc, st, rep->why);
    }
    double sec = wall() - t0, csec = cpu() - c0;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("bench=fe2 case=example1 bc=%s p=%.1f threads=%d steps=%d iterations=%ld "
           "corrections=%ld cuts=%ld seconds=%.2f s_per_iteration=%.4f cpu_seconds=%.2f "
           "peak_rss_kb=%ld converged=%d load=%.2f\n",
           bc, pressure, threads, steps, iterations, corrections, cuts, sec,
           iterations ? sec / (double)iterations : NAN, csec, ru.ru_maxrss, ok, ld);
    fflush(stdout);
    free(uD);
    free(fext);
    free(rep);
    pk_fe2_state_free(&s);
    pk_par_free(pool);
    rve_mat_free(&rm);
}

int main(void)
{
    static const char *bcs[3] = {"taylor", "restricted_taylor", "periodic"};
    pk_box b;
    pk_particles p;
    make_packing(&b, &p);
    block k;
    block_init(&k);
    for (int i = 0; i < 3; i++)
        if (bc_wanted(bcs[i], 1))
            case_gp_eval(&k, &b, &p, bcs[i]);
    for (int i = 0; i < 3; i++)
        if (bc_wanted(bcs[i], i == 0)) {
            case_example1(&k, &b, &p, bcs[i], 2);
            case_example1(&k, &b, &p, bcs[i], 1);
        }
    block_free(&k);
    pk_particles_free(&p);
    return 0;
}
