/* homog_fixture.h — jammed test RVEs and committed states shared by the
 * homogenization unit tests (static helpers; include once per test binary).
 * Needs check.h included first. */
#ifndef PK_HOMOG_FIXTURE_H
#define PK_HOMOG_FIXTURE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/homog/homog_bc.h"
#include "core/space/mat3.h"
#include "core/base/rng.h"

static inline pk_homog_opts opts(double rmean)
{
    pk_homog_opts o = {.E_n = 1.0, .affine_predictor = 1};
    o.dr.tol = 1e-12;
    o.dr.abs_floor = 1e-13; /* above the round-off of forces (~1e-16·E·L·√N) */
    o.dr.max_iter = 400000;
    o.dr.lanczos_steps = 40;
    o.dr.refresh = 200;
    o.dr.skin = 0.3 * rmean;
    return o;
}

static inline void diagF(double F[9], double a, double b, double c)
{
    memset(F, 0, 9 * sizeof *F);
    F[0] = a, F[4] = b, F[8] = c;
}

/* One load step F from the RVE's reference state (a fresh committed state):
 * *out (zeroed by the caller) gets the relaxed state.  pk_homog_eval's code. */
static inline int step_from_reference(const pk_homog_rve *rve, const pk_homog_opts *o,
                                      const double F[9], pk_homog_state *out, pk_homog_step *st)
{
    pk_homog_state s0;
    if (pk_homog_state_init(rve, o, &s0) != 0)
        return -1;
    int rc = pk_homog_eval(rve, o, &s0, F, out, st, NULL);
    pk_homog_state_free(&s0);
    return rc;
}

/* max |ΔP̄| / max |P̄| of two steps */
static inline double P_rel_diff(const pk_homog_step *a, const pk_homog_step *b)
{
    double Pn = 0, d = 0;
    for (int k = 0; k < 9; k++) {
        Pn = fmax(Pn, fabs(a->P[k]));
        d = fmax(d, fabs(a->P[k] - b->P[k]));
    }
    return d / Pn;
}

/* Jammed periodic packing: n grains, radii in [0.8, 1.2], overlapping at
 * φ_nominal, relaxed to equilibrium (DR tol 1e-12). */
static inline void make_jammed(int dim, size_t n, double phi, uint64_t seed, pk_box *b,
                               pk_particles *p)
{
    pk_rng rng;
    pk_rng_seed(&rng, seed, 0);
    pk_particles_init(p, dim, n);
    double meas = 0;
    double *r = malloc(n * sizeof *r);
    for (size_t i = 0; i < n; i++) {
        r[i] = pk_rng_range(&rng, 0.8, 1.2);
        meas += pk_ball_measure(dim, r[i]);
    }
    double L = pow(meas / phi, 1.0 / dim);
    memset(b, 0, sizeof *b);
    b->dim = dim;
    for (int k = 0; k < dim; k++)
        b->L[k] = L, b->periodic[k] = true;
    for (size_t i = 0; i < n; i++) {
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            x[k] = pk_rng_range(&rng, 0, L);
        pk_particles_push(p, x, r[i], 0);
    }
    free(r);
    pk_homog_rve rve;
    char err[128];
    CHECK(pk_homog_rve_build(b, p, PK_BC_PERIODIC, 1.0, &rve, err, sizeof err) == 0);
    pk_homog_opts o = opts(1.0);
    pk_homog_state tr = {0};
    double I[9];
    pk_m3_identity(I);
    pk_homog_step st;
    CHECK(step_from_reference(&rve, &o, I, &tr, &st) == 0);
    CHECK_MSG(pk_dr_stop_ok(st.dr.stop), "jamming relaxation: %s after %zu iterations",
              pk_dr_stop_name(st.dr.stop), st.dr.iterations);
    for (size_t i = 0; i < n; i++) {
        memcpy(&p->x[3 * i], &tr.x[3 * i], 3 * sizeof(double));
        pk_box_wrap(b, &p->x[3 * i]);
    }
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
}

/* One committed state per BC after a first load step F0. */
typedef struct fixture {
    pk_homog_rve rve;
    pk_homog_opts o;
    pk_homog_state s;
    pk_homog_step st;
} fixture;

/* Committed state after F0 with options o (e.g. a species stiffness). */
static inline void fixture_make_opts(fixture *fx, const pk_box *b, const pk_particles *p,
                                     pk_homog_bc bc, const double F0[9], const pk_homog_opts *o)
{
    char err[128];
    CHECK(pk_homog_rve_build(b, p, bc, 1.0, &fx->rve, err, sizeof err) == 0);
    fx->o = *o;
    memset(&fx->s, 0, sizeof fx->s);
    CHECK(step_from_reference(&fx->rve, &fx->o, F0, &fx->s, &fx->st) == 0);
    CHECK(pk_dr_stop_ok(fx->st.dr.stop));
}

static inline void fixture_make(fixture *fx, const pk_box *b, const pk_particles *p, pk_homog_bc bc,
                                const double F0[9])
{
    pk_homog_opts o = opts(1.0);
    fixture_make_opts(fx, b, p, bc, F0, &o);
}

static inline void fixture_free(fixture *fx)
{
    pk_homog_rve_free(&fx->rve);
    pk_homog_state_free(&fx->s);
}

/* A relaxation problem for the solvers themselves (DR, FIRE): a dense
 * 200-grain packing (φ 0.90, well above jamming: one minimum near the start,
 * no plastic event) under 0.1 % compression; x0 the affine start, c the
 * RVE's pair list (not yet built), is_free the grains the solvers move. */
typedef struct relax_problem {
    pk_particles p;
    pk_homog_rve rve;
    pk_homog_opts o;
    pk_dem_geom g;
    pk_dem_pairs c;
    uint8_t *is_free;
    double *x0;
} relax_problem;

static inline void relax_problem_make(relax_problem *pb)
{
    pk_box b;
    make_jammed(2, 200, 0.90, 7, &b, &pb->p);
    char err[128];
    CHECK(pk_homog_rve_build(&b, &pb->p, PK_BC_PERIODIC, 1.0, &pb->rve, err, sizeof err) == 0);
    pb->o = opts(1.0);
    pb->o.dr.tol = 1e-10;
    double F[9];
    diagF(F, 0.999, 1.0, 1.0);
    memset(&pb->g, 0, sizeof pb->g);
    pb->g.dim = 2;
    pb->g.periodic = 1;
    memcpy(pb->g.L, pb->rve.L, sizeof pb->g.L);
    pk_dem_geom_set_F(&pb->g, F);
    memset(&pb->c, 0, sizeof pb->c);
    pk_homog_pairs_setup(&pb->c, &pb->rve, &pb->o);
    size_t n = pb->rve.n;
    pb->is_free = malloc(n);
    pb->x0 = malloc(3 * n * sizeof *pb->x0);
    for (size_t i = 0; i < n; i++) {
        pb->is_free[i] = !pb->rve.fixed[i];
        pk_m3_vec(F, &pb->rve.X[3 * i], &pb->x0[3 * i]);
        pb->x0[3 * i + 2] = 0;
    }
}

/* The system the relaxations of pb work on. */
static inline pk_dem_system relax_problem_system(relax_problem *pb)
{
    pk_dem_system s = {&pb->c, &pb->g, pb->rve.r, pb->rve.n, pb->o.E_n, pb->is_free};
    return s;
}

static inline void relax_problem_free(relax_problem *pb)
{
    pk_dem_pairs_free(&pb->c);
    pk_homog_rve_free(&pb->rve);
    pk_particles_free(&pb->p);
    free(pb->is_free);
    free(pb->x0);
}

#endif
