/* test_fe2_newton.c — the macro Newton step of FE² (issue 26): quadratic
 * convergence on a block of Taylor RVEs (the residual sequences printed,
 * beside the thesis's Table 6.1), the same bits for pool sizes 1 and 2,
 * automatic step cutting with commit after converged parts only
 * (Remark 4.4), cancellation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"
#include "fe2_fixture.h"

/* The block of §6.4.1 in small: [0,1]² in 2×2 Q1, rollers on the left
 * (u_x = 0) and bottom (u_y = 0), the top's u_y prescribed, pressure p on
 * the right edge. */
typedef struct block {
    pk_fe2_mesh m;
    int32_t fix[32];
    size_t nfix, ntop;
    size_t top[8]; /* indices into fix of the top's u_y */
    double fp[32]; /* f_ext of the pressure, [ndof] */
} block;

static void block_make(block *b, double p)
{
    memset(b, 0, sizeof *b);
    CHECK(pk_fe2_mesh_rectangle(1, 1, 2, 2, &b->m) == 0);
    for (size_t a = 0; a < b->m.nnode; a++) {
        const double x = b->m.xy[2 * a], y = b->m.xy[2 * a + 1];
        if (x == 0)
            b->fix[b->nfix++] = (int32_t)(2 * a);
        if (y == 0 || y == 1) {
            if (y == 1)
                b->top[b->ntop++] = b->nfix;
            b->fix[b->nfix++] = (int32_t)(2 * a + 1);
        }
    }
    const double t[2] = {-p, 0};
    pk_fe2_edge_traction(&b->m, 2, 5, t, b->fp); /* right edge: nodes 2, 5, 8 */
    pk_fe2_edge_traction(&b->m, 5, 8, t, b->fp);
}

/* Step 1: the pressure with the top held; step 2: the top pushed down by v.
 * Returns the step-2 report in *rep2. */
static void block_run(block *b, pk_fe2_problem *pb, pk_fe2_state *s, double v,
                      pk_fe2_step_report *rep1, pk_fe2_step_report *rep2)
{
    pk_fe2_newton_opts o = newton_opts();
    o.rtol = 1e-12;
    double uD[32] = {0};
    CHECK(pk_fe2_state_init(s, &b->m) == 0);
    int rc = pk_fe2_step(pb, &o, s, uD, b->fp, rep1, NULL);
    CHECK_MSG(rc == 0, "step 1: %s", rep1->why);
    for (size_t k = 0; k < b->ntop; k++)
        uD[b->top[k]] = -v;
    rc = pk_fe2_step(pb, &o, s, uD, b->fp, rep2, NULL);
    CHECK_MSG(rc == 0, "step 2: %s", rep2->why);
}

/* Residual order: wherever res[k] < 1e-2, res[k+1] <= max(10·res[k]²,
 * 1e-13) — quadratic down to the round-off floor (a linear rate would give
 * res[k+1] ~ c·res[k]); at least one such k above 1e-7. */
static int quadratic(const pk_fe2_iterations *it, double *worst)
{
    int ok = 1, seen = 0;
    for (int k = 0; k + 1 < it->n; k++)
        if (it->res[k] < 1e-2) {
            seen |= it->res[k] > 1e-7;
            if (it->res[k + 1] > 1e-13) {
                double c = it->res[k + 1] / (it->res[k] * it->res[k]);
                *worst = fmax(*worst, c);
                ok &= c <= 10;
            }
        }
    return ok && seen;
}

static void print_parts(const char *name, const pk_fe2_step_report *rep)
{
    for (size_t q = 0; q < rep->nparts; q++) {
        printf("  %-8s part %zu [%.3g, %.3g] |R0| %.3e:", name, q, rep->parts[q].t0,
               rep->parts[q].t1, rep->parts[q].abs_res0);
        for (int k = 0; k < rep->parts[q].n; k++)
            printf(" %.3e", rep->parts[q].res[k]);
        printf("\n");
    }
}

static void test_quadratic_taylor(void)
{
    pk_homog_rve rve;
    pk_homog_opts o;
    make_rve(60, 17, PK_BC_TAYLOR, &rve, &o);
    block b;
    block_make(&b, 0.03);
    pk_fe2_rve fr;
    char err[200];
    CHECK(pk_fe2_rve_init(&fr, &rve, 1, &o, &pk_sparse_cholmod, pk_fe2_gauss_count(&b.m), NULL, err,
                          sizeof err) == 0);
    pk_fe2_material mat = pk_fe2_rve_material(&fr);
    pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, NULL, NULL};
    pk_fe2_state s;
    pk_fe2_step_report r1, r2;
    block_run(&b, &pb, &s, 0.01, &r1, &r2);
    print_parts("pressure", &r1);
    print_parts("push", &r2);
    double worst = 0;
    CHECK(r1.converged && r2.converged && r1.cuts == 0 && r2.cuts == 0);
    CHECK_MSG(quadratic(&r1.parts[0], &worst) && quadratic(&r2.parts[0], &worst),
              "not quadratic: res[k+1]/res[k]^2 up to %g", worst);
    CHECK(r1.parts[0].n <= 7 && r2.parts[0].n <= 7);
    /* a step that moves nothing converges at once (its reference residual
     * is round-off itself) and changes nothing */
    double *u1 = malloc(s.ndof * sizeof *u1), uD[32] = {0};
    memcpy(u1, s.u, s.ndof * sizeof *u1);
    for (size_t k = 0; k < b.nfix; k++)
        uD[k] = s.u[b.fix[k]];
    pk_fe2_newton_opts o2 = newton_opts();
    o2.atol = 0;
    pk_fe2_step_report r3;
    CHECK_MSG(pk_fe2_step(&pb, &o2, &s, uD, b.fp, &r3, NULL) == 0, "hold: %s", r3.why);
    CHECK(r3.cuts == 0 && r3.nparts == 1 && r3.parts[0].n == 2);
    for (size_t d = 0; d < s.ndof; d++)
        CHECK(fabs(s.u[d] - u1[d]) <= 1e-15);
    free(u1);
    double fv = 0; /* the resultant on the bottom (nodes 0, 1, 2) */
    for (int a = 0; a < 3; a++)
        fv += s.fint[2 * a + 1] - s.fext[2 * a + 1];
    printf("  max res[k+1]/res[k]^2 = %.3g; reactions: left %.4g, bottom %.4g\n", worst,
           r2.reaction[0], fv);
    CHECK(fv > 0.01 && fabs(r2.reaction[0] - 0.03) < 1e-12); /* the pressure's resultant */
    pk_fe2_state_free(&s);
    pk_fe2_rve_free(&fr);
    pk_homog_rve_free(&rve);
    pk_fe2_mesh_free(&b.m);
}

/* The same step on pools of 1 and 2 threads: the same bits (restricted
 * Taylor: every Gauss point relaxes its RVE). */
static void test_pool_bits(void)
{
    pk_homog_rve rve[2];
    pk_homog_opts o;
    make_rve(40, 21, PK_BC_RESTRICTED_TAYLOR, &rve[0], &o);
    make_rve(40, 22, PK_BC_RESTRICTED_TAYLOR, &rve[1], &o);
    block b;
    block_make(&b, 0.03);
    pk_fe2_state s[2];
    pk_fe2_step_report r1[2], r2[2];
    for (int run = 0; run < 2; run++) {
        pk_par *par = run ? pk_par_new(2) : NULL;
        pk_fe2_rve fr;
        char err[200];
        CHECK(pk_fe2_rve_init(&fr, rve, 2, &o, &pk_sparse_cholmod, pk_fe2_gauss_count(&b.m), NULL,
                              err, sizeof err) == 0);
        pk_fe2_material mat = pk_fe2_rve_material(&fr);
        pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, par, NULL};
        block_run(&b, &pb, &s[run], 0.005, &r1[run], &r2[run]);
        if (run)
            print_parts("push", &r2[run]);
        pk_fe2_rve_free(&fr);
        pk_par_free(par);
    }
    CHECK(!memcmp(s[0].u, s[1].u, s[0].ndof * sizeof *s[0].u));
    CHECK(!memcmp(s[0].P, s[1].P, 4 * s[0].ngp * sizeof *s[0].P));
    CHECK(!memcmp(s[0].A, s[1].A, 16 * s[0].ngp * sizeof *s[0].A));
    CHECK(r2[0].parts[0].n == r2[1].parts[0].n &&
          !memcmp(r2[0].parts[0].res, r2[1].parts[0].res, sizeof r2[0].parts[0].res));
    for (int run = 0; run < 2; run++)
        pk_fe2_state_free(&s[run]);
    pk_homog_rve_free(&rve[0]);
    pk_homog_rve_free(&rve[1]);
    pk_fe2_mesh_free(&b.m);
}

/* The linear surrogate that fails when F̄ moves more than `limit` (max
 * component) away from the point's committed F̄ — a micro relaxation that
 * cannot take too large an increment.  Counts evaluations and commits. */
typedef struct picky {
    pk_fe2_linear_elastic le;
    pk_fe2_material inner;
    double limit;
    double Fc[64][4], Ft[64][4];
    size_t evals, commits;
} picky;

static int picky_eval(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                      pk_fe2_gp_info *info, char *why, size_t whylen)
{
    picky *pk = ctx;
    pk->evals++; /* serial pool: no race */
    double d = 0;
    for (int I = 0; I < 4; I++)
        d = fmax(d, fabs(F[I] - pk->Fc[g][I]));
    memcpy(pk->Ft[g], F, sizeof pk->Ft[g]);
    if (d > pk->limit) {
        snprintf(why, whylen, "increment %.3g above %.3g", d, pk->limit);
        return 1;
    }
    return pk->inner.eval(pk->inner.ctx, g, F, P, A, info, why, whylen);
}

static int picky_commit(void *ctx, size_t g)
{
    picky *pk = ctx;
    memcpy(pk->Fc[g], pk->Ft[g], sizeof pk->Fc[g]);
    pk->commits++;
    return 0;
}

static void picky_init(picky *pk, double limit)
{
    memset(pk, 0, sizeof *pk);
    pk->le = (pk_fe2_linear_elastic){.lambda = 1, .mu = 1};
    pk->inner = pk_fe2_linear_elastic_material(&pk->le);
    pk->limit = limit;
    for (int g = 0; g < 64; g++)
        pk->Fc[g][0] = pk->Fc[g][3] = 1;
}

static void test_step_cutting(void)
{
    block b;
    block_make(&b, 0.0);
    pk_fe2_state s[2];
    pk_fe2_step_report rep[2];
    double uD[32] = {0}, fz[32] = {0};
    for (size_t k = 0; k < b.ntop; k++)
        uD[b.top[k]] = -0.02; /* 2 % strain */
    for (int run = 0; run < 2; run++) {
        picky pk;
        picky_init(&pk, run ? 0.012 : 1.0); /* run 1: fails above 1.2 % */
        pk_fe2_material mat = {"picky", &pk, picky_eval, picky_commit};
        pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, NULL, NULL};
        CHECK(pk_fe2_state_init(&s[run], &b.m) == 0);
        pk_fe2_newton_opts o = newton_opts();
        int rc = pk_fe2_step(&pb, &o, &s[run], uD, fz, &rep[run], NULL);
        CHECK_MSG(rc == 0, "%s", rep[run].why);
        /* commits only after converged parts: one per Gauss point and part */
        size_t conv = 0;
        for (size_t q = 0; q < rep[run].nparts; q++)
            conv += (size_t)rep[run].parts[q].converged;
        CHECK(pk.commits == conv * s[run].ngp);
        print_parts(run ? "cut" : "uncut", &rep[run]);
    }
    CHECK(rep[0].cuts == 0 && rep[0].nparts == 1);
    CHECK(rep[1].cuts >= 1 && rep[1].nparts >= 3 && !rep[1].parts[0].converged);
    CHECK(rep[1].parts[rep[1].nparts - 1].t1 == 1.0);
    double du = 0;
    for (size_t d = 0; d < s[0].ndof; d++)
        du = fmax(du, fabs(s[0].u[d] - s[1].u[d]));
    CHECK_MSG(du < 1e-14, "cut and uncut differ by %g", du);

    /* no cut allowed: the step fails, the state and the history stay put */
    picky pk;
    picky_init(&pk, 0.012);
    pk_fe2_material mat = {"picky", &pk, picky_eval, picky_commit};
    pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, NULL, NULL};
    pk_fe2_state s0;
    CHECK(pk_fe2_state_init(&s0, &b.m) == 0);
    pk_fe2_newton_opts o = newton_opts();
    o.max_cuts = 0;
    pk_fe2_step_report r;
    CHECK(pk_fe2_step(&pb, &o, &s0, uD, fz, &r, NULL) == 1);
    CHECK(!r.converged && pk.commits == 0 && strstr(r.why, "Gauss point") &&
          strstr(r.why, "increment"));
    for (size_t d = 0; d < s0.ndof; d++)
        CHECK(s0.u[d] == 0);
    printf("  refused: %s\n", r.why);
    for (int run = 0; run < 2; run++)
        pk_fe2_state_free(&s[run]);
    pk_fe2_state_free(&s0);
    pk_fe2_mesh_free(&b.m);
}

/* A hyperelastic surrogate hardening in volume: Φ = λ/2 t² + μ ε:ε + β/4 t⁴
 * (t = tr ε), P̄ = λ t 1 + 2μ ε + β t³ 1, Ā = its exact derivative. */
static int hard_eval(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                     pk_fe2_gp_info *info, char *why, size_t whylen)
{
    const double beta = *(const double *)ctx;
    pk_fe2_linear_elastic le = {.lambda = 1, .mu = 1};
    pk_fe2_material lin = pk_fe2_linear_elastic_material(&le);
    lin.eval(lin.ctx, g, F, P, A, info, why, whylen);
    const double t = F[0] + F[3] - 2;
    P[0] += beta * t * t * t, P[3] += beta * t * t * t;
    for (int I = 0; I < 4; I += 3)
        for (int J = 0; J < 4; J += 3)
            A[4 * I + J] += 3 * beta * t * t;
    return 0;
}

static int hard_commit(void *ctx, size_t g)
{
    (void)ctx, (void)g;
    return 0;
}

/* Newton from the soft start tangent overshoots a hardening material: the
 * line search (g(1) changes sign and grows) takes s < 1 and the step
 * converges to the same equilibrium as without it, in fewer iterations. */
static void test_line_search(void)
{
    block b;
    block_make(&b, 0.05);
    double beta = 1e6;
    pk_fe2_material mat = {"hardening", &beta, hard_eval, hard_commit};
    pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, NULL, NULL};
    pk_fe2_state s[2];
    pk_fe2_step_report rep[2];
    double uD[32] = {0};
    for (int ls = 0; ls < 2; ls++) {
        CHECK(pk_fe2_state_init(&s[ls], &b.m) == 0);
        pk_fe2_newton_opts o = newton_opts();
        o.line_search = ls;
        o.max_iter = 60;
        int rc = pk_fe2_step(&pb, &o, &s[ls], uD, b.fp, &rep[ls], NULL);
        CHECK_MSG(rc == 0, "line search %d: %s", ls, rep[ls].why);
        const pk_fe2_iterations *it = &rep[ls].parts[0];
        double emin = 1;
        for (int k = 0; k + 1 < it->n; k++)
            emin = fmin(emin, it->ls_eta[k]);
        printf("  line search %d: %d residuals, smallest eta %.3g, last %.2e\n", ls, it->n, emin,
               it->res[it->n - 1]);
        CHECK(ls ? emin < 1 : emin == 1);
    }
    CHECK(rep[1].parts[0].n < rep[0].parts[0].n);
    double du = 0, un = 0;
    for (size_t d = 0; d < s[0].ndof; d++)
        du = fmax(du, fabs(s[0].u[d] - s[1].u[d])), un = fmax(un, fabs(s[0].u[d]));
    CHECK_MSG(du < 1e-9 * un, "solutions differ by %g of %g", du, un);
    for (int ls = 0; ls < 2; ls++)
        pk_fe2_state_free(&s[ls]);
    pk_fe2_mesh_free(&b.m);
}

static void test_cancel(void)
{
    block b;
    block_make(&b, 0.01);
    pk_fe2_linear_elastic le = {.lambda = 1, .mu = 1};
    pk_fe2_material mat = pk_fe2_linear_elastic_material(&le);
    pk_fe2_problem pb = {&b.m, &mat, b.nfix, b.fix, &pk_sparse_cholmod, NULL, NULL};
    volatile sig_atomic_t flag = 1;
    pk_monitor mon = {.cancel = &flag, .interval_s = 0.5};
    pk_fe2_state s;
    CHECK(pk_fe2_state_init(&s, &b.m) == 0);
    pk_fe2_newton_opts o = newton_opts();
    double uD[32] = {0};
    pk_fe2_step_report r;
    CHECK(pk_fe2_step(&pb, &o, &s, uD, b.fp, &r, &mon) == 2);
    CHECK(!r.converged && s.u[2 * 8] == 0);
    pk_fe2_state_free(&s);
    pk_fe2_mesh_free(&b.m);
}

int main(void)
{
    RUN(test_quadratic_taylor);
    RUN(test_pool_bits);
    RUN(test_step_cutting);
    RUN(test_line_search);
    RUN(test_cancel);
    return check_summary();
}
