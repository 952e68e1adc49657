/* fe2_newton.c — one macroscopic load step of FE² (Meier 2009 §6.4):
 * Newton–Raphson on the free dofs with the consistent tangent, a line
 * search, automatic step cutting, and the commit of the material after each
 * converged part only (Remark 4.4).  Contract: fe2_solver.h.
 *
 * Line search (FEAP's rule, as in the thesis's macro solver): with the
 * correction Δu and g(s) = R(u + sΔu)·Δu over the free dofs, the full step
 * s = 1 is taken unless |g(1)| > |g(0)| with g changing sign (the step
 * overshoots the minimum of the energy along Δu); then regula falsi (the
 * secant kept bracketing) on g until |g(s)| ≤ FE2_LS_TOL·|g(0)|, at most
 * FE2_LS_MAX evaluations, s ≥ FE2_LS_MIN.  A trial at which a Gauss point
 * fails halves s (line search on) or fails the part (off).
 *
 * Step cutting: a part [t0, t1] of the step (fractions of its load) fails
 * when a Gauss point fails, the tangent is singular, or max_iter corrections
 * do not converge; the state goes back to t0 (nothing was committed) and the
 * part is halved, at most max_cuts times in the step.  After a converged
 * part the step goes on with parts of the same size. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fe2_assemble.h"

#define FE2_LS_TOL 0.8
#define FE2_LS_MAX 6
#define FE2_LS_MIN 0.05
/* A residual below FE2_ROUNDOFF × max(|f_int| of the part's start, |f_ext|)
 * (all dofs) is round-off: converged whatever rtol says (a part that moves
 * nothing has a reference residual at round-off itself). */
#define FE2_ROUNDOFF 1e-13

int pk_fe2_state_init(pk_fe2_state *s, const pk_fe2_mesh *m)
{
    memset(s, 0, sizeof *s);
    s->ndof = 2 * m->nnode;
    s->ngp = pk_fe2_gauss_count(m);
    const size_t nd = s->ndof ? s->ndof : 1, ng = s->ngp ? s->ngp : 1;
    s->u = calloc(nd, sizeof *s->u);
    s->fext = calloc(nd, sizeof *s->fext);
    s->fint = calloc(nd, sizeof *s->fint);
    s->F = calloc(4 * ng, sizeof *s->F);
    s->P = calloc(4 * ng, sizeof *s->P);
    s->A = calloc(16 * ng, sizeof *s->A);
    s->gp = calloc(ng, sizeof *s->gp);
    if (!s->u || !s->fext || !s->fint || !s->F || !s->P || !s->A || !s->gp) {
        pk_fe2_state_free(s);
        return -1;
    }
    for (size_t g = 0; g < s->ngp; g++)
        s->F[4 * g] = s->F[4 * g + 3] = 1;
    return 0;
}

void pk_fe2_state_free(pk_fe2_state *s)
{
    free(s->u), free(s->fext), free(s->fint), free(s->F), free(s->P), free(s->A), free(s->gp);
    memset(s, 0, sizeof *s);
}

/* Everything one step works with. */
typedef struct step_ws {
    const pk_fe2_problem *pb;
    const pk_fe2_newton_opts *o;
    pk_monitor *mon;
    size_t ndof, nfree, evals;
    int32_t *map;  /* [ndof] free index or −1 */
    double *u;     /* [ndof] the iterate */
    double *utry;  /* [ndof] a line-search trial */
    double *fext;  /* [ndof] f_ext of the part's end */
    double *fint;  /* [ndof] */
    double *rhs;   /* [nfree] −R_free */
    double *du;    /* [nfree] */
    double *delta; /* [ndof] the part's prescribed increments, 0 on free dofs */
    pk_sparse_sym K;
    fe2_gp_buf b;
    char why[256];
} step_ws;

enum { PART_CONVERGED = 0, PART_FAILED = 1, PART_CANCELLED = 2, PART_FATAL = -1 };

/* One evaluation round at u, with the monitor's tick. */
static int round_at(step_ws *w, const double *u)
{
    int rc = fe2_eval_round(w->pb, u, &w->b, w->mon ? w->mon->cancel : NULL, w->why, sizeof w->why);
    w->evals += w->b.ngp;
    if (rc == FE2_ROUND_CANCELLED)
        return PART_CANCELLED;
    if (rc == FE2_ROUND_LOST)
        return PART_FATAL;
    pk_progress pr = {.stage = "fe2", .fraction = -1, .phi = -1, .done = w->evals, .eta_s = -1};
    if (w->mon && pk_monitor_tick(w->mon, &pr, 0) != 0) {
        snprintf(w->why, sizeof w->why, "cancelled or out of time");
        return PART_CANCELLED;
    }
    return rc == FE2_ROUND_OK ? PART_CONVERGED : PART_FAILED;
}

/* R(u) over the free dofs into rhs as −R (fint from the last round). */
static double free_residual(step_ws *w)
{
    fe2_internal_force(w->pb, &w->b, w->fint);
    double r2 = 0;
    for (size_t d = 0; d < w->ndof; d++)
        if (w->map[d] >= 0) {
            const double R = w->fint[d] - w->fext[d];
            w->rhs[w->map[d]] = -R;
            r2 += R * R;
        }
    return sqrt(r2);
}

static double dot_free(const step_ws *w, const double *a)
{
    double s = 0;
    for (size_t k = 0; k < w->nfree; k++)
        s += a[k] * w->du[k];
    return s;
}

static void trial_point(step_ws *w, double s)
{
    memcpy(w->utry, w->u, w->ndof * sizeof *w->u);
    for (size_t d = 0; d < w->ndof; d++)
        if (w->map[d] >= 0)
            w->utry[d] += s * w->du[w->map[d]];
}

/* Move u along du (the rule in the file's comment); on return the last
 * round was evaluated at the new u and rhs holds its −R.  *eta the factor. */
static int line_search(step_ws *w, double *eta)
{
    const double g0 = -dot_free(w, w->rhs); /* R(u)·Δu */
    double s = 1;
    int rc;
    for (int halvings = 0;; halvings++) {
        trial_point(w, s);
        rc = round_at(w, w->utry);
        if (rc != PART_FAILED || !w->o->line_search || halvings == 3)
            break;
        s *= 0.5;
    }
    if (rc != PART_CONVERGED)
        return rc;
    free_residual(w);
    double g = -dot_free(w, w->rhs);
    if (w->o->line_search && fabs(g) > fabs(g0) && g0 < 0 && g > 0) {
        double sa = 0, ga = g0, sb = s, gb = g;
        for (int it = 0; it < FE2_LS_MAX && fabs(g) > FE2_LS_TOL * fabs(g0); it++) {
            double sn = sb - gb * (sb - sa) / (gb - ga);
            sn = fmin(fmax(sn, FE2_LS_MIN), 1.0);
            if (sn == s)
                break;
            s = sn;
            trial_point(w, s);
            rc = round_at(w, w->utry);
            if (rc == PART_CANCELLED)
                return rc;
            if (rc == PART_FAILED) { /* too far: shrink the bracket */
                sb = s, gb = fabs(g0);
                g = gb;
                continue;
            }
            free_residual(w);
            g = -dot_free(w, w->rhs);
            if (g < 0)
                sa = s, ga = g;
            else
                sb = s, gb = g;
        }
        if (rc == PART_FAILED) { /* the last trial failed: back to the bracket's low end */
            if (sa == 0)
                return PART_FAILED;
            s = sa;
            trial_point(w, s);
            if ((rc = round_at(w, w->utry)) != PART_CONVERGED)
                return rc;
            free_residual(w);
        }
    }
    memcpy(w->u, w->utry, w->ndof * sizeof *w->u);
    *eta = s;
    return PART_CONVERGED;
}

/* The tangent predictor of the part (fe2_solver.h): from the converged
 * state s (its A and fint), the prescribed increments delta [ndof] (0 on the
 * free dofs) and w->fext: w->u = s->u + Δu_D, the linearised −R in rhs, its
 * norm in *r_ref, and with *have_du the correction Δu_f in du (none when
 * the start has no usable tangent, e.g. a loose packing). */
static int predictor(step_ws *w, const pk_fe2_state *s, const double *delta, double *r_ref,
                     int *have_du)
{
    const pk_fe2_problem *pb = w->pb;
    *have_du = 0;
    memcpy(w->b.A, s->A, 16 * w->b.ngp * sizeof *s->A);
    double *Kd = w->utry; /* scratch: K·Δu_D over all dofs */
    if (fe2_stiffness(pb, &w->b, NULL, w->ndof, &w->K) != 0)
        return PART_FATAL;
    pk_sparse_sym_mv(&w->K, delta, Kd);
    double r2 = 0;
    for (size_t d = 0; d < w->ndof; d++) {
        w->u[d] = s->u[d] + delta[d];
        if (w->map[d] >= 0) {
            const double R = s->fint[d] - w->fext[d] + Kd[d];
            w->rhs[w->map[d]] = -R;
            r2 += R * R;
        }
    }
    *r_ref = sqrt(r2);
    if (!(*r_ref > 0) || w->nfree == 0)
        return PART_CONVERGED;
    if (fe2_stiffness(pb, &w->b, w->map, w->nfree, &w->K) != 0)
        return PART_FATAL;
    pk_sparse_info info;
    pk_sparse_factor *f = pb->solver->factor(&w->K, &info);
    if (!f)
        return info.status == PK_SPARSE_FAILED ? PART_FATAL : PART_CONVERGED;
    int src = pb->solver->solve(f, 1, w->rhs, w->du);
    pb->solver->release(f);
    if (src != 0)
        return PART_FATAL;
    *have_du = 1;
    return PART_CONVERGED;
}

static double norm_free(const step_ws *w)
{
    double r = 0;
    for (size_t q = 0; q < w->nfree; q++)
        r += w->rhs[q] * w->rhs[q];
    return sqrt(r);
}

/* One part: the predictor from s, then Newton to equilibrium under w->fext. */
static int newton(step_ws *w, const pk_fe2_state *s, const double *delta, pk_fe2_iterations *it)
{
    const pk_fe2_problem *pb = w->pb;
    const pk_fe2_newton_opts *o = w->o;
    double r0, r, eta = 1;
    int have_du, rc = predictor(w, s, delta, &r0, &have_du);
    if (rc != PART_CONVERGED) {
        snprintf(w->why, sizeof w->why, "out of memory or solver failure (predictor)");
        return rc;
    }
    it->abs_res0 = r0;
    it->res[it->n++] = 1;
    double fi = 0, fe = 0;
    for (size_t d = 0; d < w->ndof; d++)
        fi += s->fint[d] * s->fint[d], fe += w->fext[d] * w->fext[d];
    const double rfloor = FE2_ROUNDOFF * sqrt(fmax(fi, fe));
    /* the predictor's correction takes the line search too: g(0) is the
     * linearised residual's R·Δu */
    if (have_du)
        rc = line_search(w, &eta);
    else if ((rc = round_at(w, w->u)) == PART_CONVERGED)
        free_residual(w);
    if (rc != PART_CONVERGED)
        return rc;
    it->ls_eta[0] = eta;
    r = norm_free(w);
    if (!(r0 > 0))
        r0 = r;
    for (int k = 1;; k++) {
        const double rel = r0 > 0 ? r / r0 : 0;
        if (it->n < 64)
            it->res[it->n++] = rel;
        if (!isfinite(r)) {
            snprintf(w->why, sizeof w->why, "residual not finite");
            return PART_FAILED;
        }
        if (r <= o->atol || rel <= o->rtol || r <= rfloor) {
            it->converged = 1;
            return PART_CONVERGED;
        }
        if (k > o->max_iter) {
            snprintf(w->why, sizeof w->why,
                     "no convergence in %d iterations (relative residual %.3g)", o->max_iter, rel);
            return PART_FAILED;
        }
        if (fe2_stiffness(pb, &w->b, w->map, w->nfree, &w->K) != 0) {
            snprintf(w->why, sizeof w->why, "out of memory");
            return PART_FATAL;
        }
        pk_sparse_info info;
        pk_sparse_factor *f = pb->solver->factor(&w->K, &info);
        if (!f) {
            snprintf(w->why, sizeof w->why, "macro tangent %s", pk_sparse_status_name(info.status));
            return info.status == PK_SPARSE_FAILED ? PART_FATAL : PART_FAILED;
        }
        int src = pb->solver->solve(f, 1, w->rhs, w->du);
        pb->solver->release(f);
        if (src != 0) {
            snprintf(w->why, sizeof w->why, "macro solve failed");
            return PART_FATAL;
        }
        eta = 1;
        if ((rc = line_search(w, &eta)) != PART_CONVERGED)
            return rc;
        if (k < 64)
            it->ls_eta[k] = eta;
        r = norm_free(w);
    }
}

static void ws_free(step_ws *w)
{
    free(w->map), free(w->u), free(w->utry), free(w->fext), free(w->fint), free(w->rhs);
    free(w->du), free(w->delta);
    pk_sparse_sym_free(&w->K);
    fe2_gp_buf_free(&w->b);
}

static int ws_init(step_ws *w, const pk_fe2_problem *pb)
{
    const size_t nd = w->ndof ? w->ndof : 1;
    w->map = malloc(nd * sizeof *w->map);
    w->u = malloc(nd * sizeof *w->u);
    w->utry = malloc(nd * sizeof *w->utry);
    w->fext = malloc(nd * sizeof *w->fext);
    w->fint = calloc(nd, sizeof *w->fint);
    w->rhs = calloc(nd, sizeof *w->rhs);
    w->du = calloc(nd, sizeof *w->du);
    w->delta = calloc(nd, sizeof *w->delta);
    if (!w->delta || !w->map || !w->u || !w->utry || !w->fext || !w->fint || !w->rhs || !w->du ||
        fe2_gp_buf_init(&w->b, pb->mesh) != 0) {
        snprintf(w->why, sizeof w->why, "out of memory");
        return -1;
    }
    for (size_t d = 0; d < w->ndof; d++)
        w->map[d] = 0;
    for (size_t k = 0; k < pb->nfix; k++) {
        const int32_t d = pb->fix_dof[k];
        if (d < 0 || (size_t)d >= w->ndof || w->map[d] < 0) {
            snprintf(w->why, sizeof w->why, "prescribed dof %ld out of range or repeated", (long)d);
            return -1;
        }
        w->map[d] = -1;
    }
    for (size_t d = 0; d < w->ndof; d++)
        if (w->map[d] >= 0)
            w->map[d] = (int32_t)w->nfree++;
    return 0;
}

/* The last round's Gauss-point fields and f_int into s. */
static void keep_round(const step_ws *w, pk_fe2_state *s)
{
    memcpy(s->fint, w->fint, w->ndof * sizeof *s->fint);
    memcpy(s->F, w->b.F, 4 * w->b.ngp * sizeof *s->F);
    memcpy(s->P, w->b.P, 4 * w->b.ngp * sizeof *s->P);
    memcpy(s->A, w->b.A, 16 * w->b.ngp * sizeof *s->A);
    memcpy(s->gp, w->b.info, w->b.ngp * sizeof *s->gp);
    s->evaluated = 1;
}

/* The converged part becomes the state: commit every Gauss point (those
 * of other evaluators through pb->dist). */
static int accept_part(step_ws *w, pk_fe2_state *s)
{
    const pk_fe2_distributor *d = w->pb->dist;
    const size_t lo = d ? d->lo : 0, hi = d ? d->hi : w->b.ngp;
    if (pk_fe2_commit_block(w->pb, lo, hi) != 0) {
        snprintf(w->why, sizeof w->why, "out of memory (commit of the Gauss points)");
        return -1;
    }
    if (d && d->commit(d->ctx, w->why, sizeof w->why) != PK_FE2_DIST_OK)
        return -1;
    memcpy(s->u, w->u, w->ndof * sizeof *s->u);
    memcpy(s->fext, w->fext, w->ndof * sizeof *s->fext);
    keep_round(w, s);
    return 0;
}

/* A state never evaluated (the first step): the material at s->u, a trial
 * from the committed history at the same F̄ (nothing committed), for the
 * predictor's tangent and f_int. */
static int evaluate_state(step_ws *w, pk_fe2_state *s)
{
    int rc = round_at(w, s->u);
    if (rc != PART_CONVERGED)
        return rc;
    fe2_internal_force(w->pb, &w->b, w->fint);
    keep_round(w, s);
    return PART_CONVERGED;
}

int pk_fe2_step(const pk_fe2_problem *pb, const pk_fe2_newton_opts *o, pk_fe2_state *s,
                const double *uD_target, const double *fext_target, pk_fe2_step_report *rep,
                pk_monitor *mon)
{
    memset(rep, 0, sizeof *rep);
    step_ws w = {.pb = pb, .o = o, .mon = mon, .ndof = s->ndof};
    double *uD0 = malloc((pb->nfix ? pb->nfix : 1) * sizeof *uD0),
           *fext0 = malloc((s->ndof ? s->ndof : 1) * sizeof *fext0);
    int ret = -1;
    if (!uD0 || !fext0 || ws_init(&w, pb) != 0) {
        snprintf(rep->why, sizeof rep->why, "%s", w.why[0] ? w.why : "out of memory");
        goto out;
    }
    for (size_t k = 0; k < pb->nfix; k++)
        uD0[k] = s->u[pb->fix_dof[k]];
    memcpy(fext0, s->fext, s->ndof * sizeof *fext0);
    if (!s->evaluated) {
        int rc = evaluate_state(&w, s);
        if (rc != PART_CONVERGED) {
            snprintf(rep->why, sizeof rep->why, "the start state: %.230s", w.why);
            ret = rc == PART_CANCELLED ? 2 : rc == PART_FAILED ? 1 : -1;
            goto out;
        }
    }
    double t0 = 0, dt = 1;
    while (t0 < 1) {
        const double t1 = fmin(t0 + dt, 1.0);
        pk_fe2_iterations scratch, *it = rep->nparts < 32 ? &rep->parts[rep->nparts++] : &scratch;
        memset(it, 0, sizeof *it);
        it->t0 = t0, it->t1 = t1;
        for (size_t k = 0; k < pb->nfix; k++) {
            const int32_t d = pb->fix_dof[k];
            w.delta[d] = uD0[k] + t1 * (uD_target[k] - uD0[k]) - s->u[d];
        }
        for (size_t d = 0; d < s->ndof; d++)
            w.fext[d] = fext0[d] + t1 * (fext_target[d] - fext0[d]);
        w.why[0] = 0;
        int rc = newton(&w, s, w.delta, it);
        if (rc == PART_CONVERGED) {
            if (accept_part(&w, s) != 0) {
                snprintf(rep->why, sizeof rep->why, "%s", w.why);
                goto out;
            }
            t0 = t1;
            continue;
        }
        if (rc != PART_FAILED) {
            snprintf(rep->why, sizeof rep->why, "%s", w.why);
            ret = rc == PART_CANCELLED ? 2 : -1;
            goto out;
        }
        if (rep->cuts >= o->max_cuts) {
            snprintf(rep->why, sizeof rep->why,
                     "step not converged at %.4g of its load after %d cuts: %.180s", t0, rep->cuts,
                     w.why);
            ret = 1;
            goto out;
        }
        rep->cuts++;
        dt = 0.5 * (t1 - t0);
    }
    rep->converged = 1;
    ret = 0;
out:
    for (size_t k = 0; k < pb->nfix; k++) {
        const int32_t d = pb->fix_dof[k];
        if (d >= 0 && (size_t)d < s->ndof)
            rep->reaction[d % 2] += s->fint[d] - s->fext[d];
    }
    rep->rounds = w.b.ngp ? w.evals / w.b.ngp : 0;
    ws_free(&w);
    free(uD0), free(fext0);
    return ret;
}
