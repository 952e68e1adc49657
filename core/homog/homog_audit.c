/* homog_audit.c — the checks every load step passes before it counts as
 * successful (converged, balanced, contained, finite, overlap).  Contract: homog_audit.h. */
#include "homog_audit.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/space/mat3.h"

static int all_finite(const double *v, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(v[k]))
            return 0;
    return 1;
}

/* Excursion of the centre x of a free grain beyond its cell, in the
 * reference frame, in units of its radius (0 inside). */
static double excursion(const pk_homog_rve *rve, const double Finv[9], const double *x, size_t i)
{
    double X[3];
    pk_m3_vec(Finv, x, X);
    double d = 0;
    for (int a = 0; a < rve->dim; a++) {
        if (rve->bc == PK_BC_PERIODIC) {
            double xi = fabs(X[a] - rve->X[3 * i + a]);
            d = fmax(d, xi - rve->L[a]);
        } else {
            double tol = 1e-9 * rve->L[a]; /* a centre on the boundary, to round-off */
            d = fmax(d, fmax(-X[a], X[a] - rve->L[a]) - tol);
        }
    }
    if (!(d == d))
        return INFINITY;
    return d > 0 ? d / rve->r[i] : 0;
}

unsigned pk_homog_audit_step(const pk_homog_rve *rve, const pk_homog_opts *o,
                             const pk_homog_state *s, const pk_homog_step *st, pk_homog_audit *a)
{
    memset(a, 0, sizeof *a);
    a->target = fmax(o->dr.tol * st->dr.f0, o->dr.abs_floor);
    int relaxed = st->dr.stop != PK_DR_NOT_NEEDED;
    a->residual_ratio = relaxed ? st->dr.f / a->target : 0;
    a->balance_ratio = st->free_force > 0 ? st->free_force / a->target : 0;
    if (!pk_dr_stop_ok(st->dr.stop) || !(a->residual_ratio <= 1))
        a->failed |= PK_AUDIT_NOT_CONVERGED;
    if (!(a->balance_ratio <= PK_AUDIT_BALANCE_SLACK))
        a->failed |= PK_AUDIT_UNBALANCED;
    double Finv[9];
    int inv = pk_m3_inv(s->F, Finv) != 0;
    int fin = inv && all_finite(s->x, 3 * s->n) && (!s->u || all_finite(s->u, s->n)) &&
        all_finite(st->P, 9) && all_finite(st->sigma, 9) && isfinite(st->energy) &&
        isfinite(st->energy_t) && isfinite(st->dissipation) && isfinite(st->J);
    if (!fin)
        a->failed |= PK_AUDIT_NOT_FINITE;
    for (size_t i = 0; inv && i < rve->n; i++) {
        if (rve->fixed[i])
            continue;
        double e = excursion(rve, Finv, &s->x[3 * i], i);
        if (e > 0) {
            a->outside++;
            a->escape = fmax(a->escape, e);
        }
    }
    if (a->outside)
        a->failed |= PK_AUDIT_ESCAPED;
    a->overlap_ratio = st->max_overlap_ratio;
    if (!(a->overlap_ratio <= PK_AUDIT_OVERLAP_MAX))
        a->failed |= PK_AUDIT_OVERLAP;
    return a->failed;
}

void pk_homog_audit_describe(const pk_homog_audit *a, const pk_homog_step *st, char *buf,
                             size_t len)
{
    size_t n = 0;
    buf[0] = 0;
#define ADD(...)                                                                                   \
    do {                                                                                           \
        if (n < len)                                                                               \
            n += (size_t)snprintf(buf + n, len - n, __VA_ARGS__);                                  \
    } while (0)
    if (a->failed & PK_AUDIT_NOT_CONVERGED)
        ADD("%sthe relaxation did not converge (stop %s after %zu iterations, residual %.3g = "
            "%.3g × its target %.3g)",
            n ? "; " : "", pk_dr_stop_name(st->dr.stop), st->dr.iterations, st->dr.f,
            a->residual_ratio, a->target);
    if (a->failed & PK_AUDIT_UNBALANCED)
        ADD("%sthe free grains are not in equilibrium (|f| %.3g = %.3g × the target)",
            n ? "; " : "", st->free_force, a->balance_ratio);
    if (a->failed & PK_AUDIT_ESCAPED)
        ADD("%s%zu grain(s) left their cell (the farthest by %.3g radii)", n ? "; " : "",
            a->outside, a->escape);
    if (a->failed & PK_AUDIT_NOT_FINITE)
        ADD("%snon-finite stresses, energies or positions", n ? "; " : "");
    if (a->failed & PK_AUDIT_OVERLAP)
        ADD("%sthe largest overlap is %.3g × the smaller radius (bound %g: a centre inside its "
            "neighbour)",
            n ? "; " : "", a->overlap_ratio, PK_AUDIT_OVERLAP_MAX);
#undef ADD
}
