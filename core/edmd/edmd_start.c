/* edmd_start.c — EDMD parameters' defaults, criterion names and the RSA start
 * configuration at reduced size δ·d (Titscher §6.2, Kansal).
 * Contract: core/edmd/edmd.h. */
#include <math.h>
#include <stdlib.h>

#include "edmd.h"

/* The engine's defaults are the jobs' too: the edmd option table presets with
 * them (api/pack/pack_place_edmd.c), and its test holds the schema's equal. */
void pk_edmd_params_default(pk_edmd_params *prm)
{
    *prm = (pk_edmd_params){
        .growth = PK_EDMD_GROW_RELATIVE,
        .until = PK_EDMD_UNTIL_TARGET,
        .start_zero = 1, /* the engine's; jobs start from RSA (api/pack/pack_place_edmd.c) */
        .delta = 0.9,
        .growth_rate = 0.01,
        .p_max = 1e12,
        .jam_rate_factor = 0.1,
        .jam_full_rate_p = INFINITY,
        .dphi_crit = 0,
        .dphi_events = 0,
        .stall_growth = NAN,
        .stall_events = 1000,
        .rescale = 1,
        .rescale_tol = 0.1,
        .skin = 0.6,
        .equal_masses = 1,
        .seed = 1,
    };
}

const char *pk_edmd_criterion_name(pk_edmd_criterion c)
{
    static const char *names[] = {"none",       "target",    "pressure",  "delta_phi", "stall",
                                  "max_events", "cancelled", "wall_time", "error"};
    return (unsigned)c < sizeof names / sizeof *names ? names[c] : "unknown";
}

int pk_edmd_start_rsa(const pk_box *b, const double *d, const int32_t *species, size_t n,
                      double delta, double delta_d, uint64_t seed, pk_monitor *mon, pk_particles *p,
                      pk_rsa_stats *rs)
{
    if (!(delta > 0) || delta > 1)
        return -1;
    double *dd = malloc((n ? n : 1) * sizeof *dd);
    if (!dd)
        return -1;
    for (size_t i = 0; i < n; i++)
        dd[i] = delta * d[i];
    pk_rsa_params prm = {.delta_d = delta_d, .max_failed_draws = 1000000, .seed = seed};
    size_t first = p->n;
    int rc = pk_rsa_place(b, dd, species, n, &prm, mon, p, rs);
    free(dd);
    if (rc != 0)
        return -1;
    for (size_t i = first; i < p->n; i++)
        p->r[i] /= delta; /* back to the target radius; the engine starts at δ·r */
    return 0;
}

/* The fraction filled at δ = x: the cubic (2D: c[3] = 0) of the moments. */
static double start_filled(const double c[4], double x)
{
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]));
}

double pk_edmd_start_delta(int dim, const double *d, size_t n, double delta_d, double box_measure,
                           double phi_start)
{
    if ((dim != 2 && dim != 3) || !(box_measure > 0) || !(phi_start > 0))
        return 0;
    /* Σ (δ a_i + h)^dim = Σ_k C(dim, k) δ^k h^(dim−k) Σ a_i^k, a_i = d_i/2 */
    double mom[4] = {(double)n, 0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        const double a = 0.5 * d[i];
        mom[1] += a;
        mom[2] += a * a;
        mom[3] += a * a * a;
    }
    const double h = 0.5 * delta_d, unit = pk_ball_measure(dim, 1);
    const double binom[2][4] = {{1, 2, 1, 0}, {1, 3, 3, 1}};
    double c[4] = {0, 0, 0, 0};
    for (int k = 0; k <= dim; k++)
        c[k] = unit * binom[dim - 2][k] * pow(h, dim - k) * mom[k] / box_measure;
    double lo = 0, hi = PK_EDMD_START_DELTA_MAX;
    if (start_filled(c, hi) <= phi_start)
        return hi;
    if (start_filled(c, lo) > phi_start)
        return 0;
    for (int it = 0; it < 60; it++) { /* bisection: the fill grows with δ */
        const double mid = 0.5 * (lo + hi);
        if (start_filled(c, mid) <= phi_start)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}
