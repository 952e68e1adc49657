/* homog_rve.c — the discrete RVE of a packing per boundary condition (Meier
 * 2009 §3.5, §4.3): hull, unfolding, periodic primaries.  Contract: homog_rve.h. */
#include "homog_rve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *pk_homog_bc_name(pk_homog_bc bc)
{
    switch (bc) {
    case PK_BC_TAYLOR: return "taylor";
    case PK_BC_RESTRICTED_TAYLOR: return "restricted_taylor";
    case PK_BC_PERIODIC: return "periodic";
    }
    return "unknown";
}

void pk_homog_rve_free(pk_homog_rve *rve)
{
    free(rve->X);
    free(rve->r);
    free(rve->grain);
    free(rve->species);
    free(rve->fixed);
    free(rve->hull);
    memset(rve, 0, sizeof *rve);
}

static int rve_alloc(pk_homog_rve *rve, size_t cap)
{
    rve->X = calloc(3 * cap, sizeof *rve->X);
    rve->r = calloc(cap, sizeof *rve->r);
    rve->grain = calloc(cap, sizeof *rve->grain);
    rve->species = calloc(cap, sizeof *rve->species);
    rve->fixed = calloc(cap, 1);
    rve->hull = calloc(cap, 1);
    if (!rve->X || !rve->r || !rve->grain || !rve->species || !rve->fixed || !rve->hull) {
        pk_homog_rve_free(rve);
        return -1;
    }
    return 0;
}

int pk_homog_rve_from_arrays(int dim, pk_homog_bc bc, size_t n, const double *X, const double *r,
                             const uint8_t *fixed, int periodic, const double L[3], double V,
                             pk_homog_rve *rve)
{
    memset(rve, 0, sizeof *rve);
    if (rve_alloc(rve, n ? n : 1) != 0)
        return -1;
    rve->dim = dim;
    rve->bc = bc;
    rve->n = n;
    rve->periodic = periodic;
    for (int k = 0; k < 3; k++)
        rve->L[k] = L ? L[k] : 0;
    rve->V = V;
    rve->hull_gap = NAN;
    memcpy(rve->X, X, 3 * n * sizeof *X);
    memcpy(rve->r, r, n * sizeof *r);
    memcpy(rve->fixed, fixed, n);
    memcpy(rve->hull, fixed, n);
    for (size_t i = 0; i < n; i++)
        rve->grain[i] = (int32_t)i;
    return 0;
}

static int build_periodic(const pk_box *b, const pk_particles *p, double f, pk_homog_rve *rve,
                          char *err, size_t errlen)
{
    for (int k = 0; k < b->dim; k++)
        if (!b->periodic[k]) {
            snprintf(err, errlen,
                     "periodic boundary conditions need a packing periodic on every axis");
            return -1;
        }
    if (rve_alloc(rve, p->n ? p->n : 1) != 0) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    rve->n = p->n;
    rve->periodic = 1;
    rve->hull_gap = NAN;
    for (size_t i = 0; i < p->n; i++) {
        for (int k = 0; k < 3; k++)
            rve->X[3 * i + k] = k < b->dim ? p->x[3 * i + k] : 0;
        rve->r[i] = p->r[i] * f;
        rve->grain[i] = (int32_t)i;
    }
    if (p->n)
        rve->fixed[0] = rve->hull[0] = 1; /* the pinned grain */
    return 0;
}

typedef struct side_key {
    double along;
    size_t i;
} side_key;

static int by_along(const void *a, const void *b)
{
    double u = ((const side_key *)a)->along, v = ((const side_key *)b)->along;
    return (u > v) - (u < v);
}

/* rve->hull_gap (homog_rve.h) of a 2D unfolded RVE: per side, the hull
 * particles meeting it (the hull's band, as in build_unfolded) in order
 * along it, and the gaps between consecutive ones.  -1: out of memory. */
static int measure_hull_gap(pk_homog_rve *rve, const double band[2])
{
    rve->hull_gap = NAN;
    if (rve->dim != 2)
        return 0;
    side_key *key = malloc((rve->n ? rve->n : 1) * sizeof *key);
    if (!key)
        return -1;
    double dmin = INFINITY, widest = 0;
    for (size_t i = 0; i < rve->n; i++)
        dmin = fmin(dmin, 2 * rve->r[i]);
    for (int a = 0; a < 2; a++)
        for (int hi = 0; hi < 2; hi++) {
            size_t m = 0;
            for (size_t i = 0; i < rve->n; i++) {
                const double *X = &rve->X[3 * i];
                int meets =
                    hi ? X[a] + rve->r[i] >= rve->L[a] - band[a] : X[a] - rve->r[i] <= band[a];
                if (rve->hull[i] && meets)
                    key[m++] = (side_key){X[1 - a], i};
            }
            qsort(key, m, sizeof *key, by_along);
            for (size_t k = 1; k < m; k++) {
                const double *P = &rve->X[3 * key[k - 1].i], *Q = &rve->X[3 * key[k].i];
                double gap =
                    hypot(Q[0] - P[0], Q[1] - P[1]) - rve->r[key[k - 1].i] - rve->r[key[k].i];
                widest = fmax(widest, gap);
            }
        }
    free(key);
    rve->hull_gap = dmin < INFINITY ? widest / dmin : NAN;
    return 0;
}

/* Taylor / restricted Taylor: replicas on periodic axes, hull by (3.14). */
static int build_unfolded(const pk_box *b, const pk_particles *p, double f, pk_homog_rve *rve,
                          char *err, size_t errlen)
{
    const int dim = b->dim;
    size_t cap = p->n * (dim == 2 ? 4 : 8) + 1;
    if (rve_alloc(rve, cap) != 0) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    double dmin = INFINITY;
    for (size_t i = 0; i < p->n; i++)
        dmin = fmin(dmin, 2 * p->r[i] * f);
    size_t n = 0;
    for (size_t i = 0; i < p->n; i++) {
        double ri = p->r[i] * f;
        const double *x = &p->x[3 * i];
        /* shifts per axis: 0, and +L / −L when the grain crosses the low / high side */
        double sh[3][3];
        int ns[3] = {1, 1, 1};
        for (int k = 0; k < 3; k++) {
            sh[k][0] = 0;
            if (k >= dim || !b->periodic[k])
                continue;
            if (x[k] - ri < 0)
                sh[k][ns[k]++] = b->L[k];
            if (x[k] + ri > b->L[k])
                sh[k][ns[k]++] = -b->L[k];
        }
        for (int a = 0; a < ns[0]; a++)
            for (int c = 0; c < ns[1]; c++)
                for (int e = 0; e < ns[2]; e++) {
                    double *X = &rve->X[3 * n];
                    X[0] = x[0] + sh[0][a];
                    X[1] = x[1] + sh[1][c];
                    X[2] = dim == 3 ? x[2] + sh[2][e] : 0;
                    rve->r[n] = ri;
                    rve->grain[n] = (int32_t)i;
                    int hull = 0;
                    for (int k = 0; k < dim; k++) {
                        double band = b->periodic[k] ? 0 : dmin;
                        if (X[k] - ri <= band || X[k] + ri >= b->L[k] - band)
                            hull = 1;
                    }
                    rve->hull[n] = (uint8_t)hull;
                    n++;
                }
    }
    rve->n = n;
    for (size_t i = 0; i < n; i++)
        rve->fixed[i] = rve->bc == PK_BC_TAYLOR ? 1 : rve->hull[i];
    for (int k = 0; k < 3; k++)
        rve->L[k] = k < dim ? b->L[k] : 0;
    rve->dim = dim;
    double band[2] = {b->periodic[0] ? 0 : dmin, b->periodic[1] ? 0 : dmin};
    if (measure_hull_gap(rve, band) != 0) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    return 0;
}

int pk_homog_rve_build(const pk_box *b, const pk_particles *p, pk_homog_bc bc, double radius_factor,
                       pk_homog_rve *rve, char *err, size_t errlen)
{
    memset(rve, 0, sizeof *rve);
    if (!(radius_factor >= 1) || !isfinite(radius_factor)) {
        snprintf(err, errlen, "radius factor must be >= 1");
        return -1;
    }
    rve->dim = b->dim;
    rve->bc = bc;
    rve->V = pk_box_measure(b);
    for (int k = 0; k < 3; k++)
        rve->L[k] = k < b->dim ? b->L[k] : 0;
    int rc = bc == PK_BC_PERIODIC ? build_periodic(b, p, radius_factor, rve, err, errlen)
                                  : build_unfolded(b, p, radius_factor, rve, err, errlen);
    if (rc != 0)
        return -1;
    for (size_t i = 0; i < rve->n; i++)
        rve->species[i] = p->species ? p->species[rve->grain[i]] : 0;
    rve->dim = b->dim;
    rve->bc = bc;
    rve->V = pk_box_measure(b);
    for (int k = 0; k < 3; k++)
        rve->L[k] = k < b->dim ? b->L[k] : 0;
    return 0;
}
