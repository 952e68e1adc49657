/* rsa_voxels.c — the voxel set of space not yet known to be covered, for the
 * one-grain-at-a-time path.  Contract: rsa_voxels.h. */
#include "rsa_voxels.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NO_SLOT UINT32_MAX
#define MAX_VOXELS ((uint64_t)1 << 31)

/* Voxel edge bound: a voxel's diagonal stays below the smallest contact
 * distance 2 r_valid + Δd, so it holds at most one centre (rsa_voxels.h). */
static double edge_bound(int dim, double r_valid, double gap)
{
    return (2 * r_valid + gap) / sqrt((double)dim) * (1 - 1e-9);
}

/* Per-axis lattice: origin, span and voxel count; 0 if the axis cannot be tiled. */
static int axis_lattice(const pk_box *b, int k, double r_valid, double r_top, double gap,
                        double wall, double *org, double *span, int64_t *n)
{
    double e = edge_bound(b->dim, r_valid, gap);
    if (b->periodic[k]) {
        if (!(b->L[k] > 2 * (2 * r_top + gap)))
            return 0; /* a grain could meet two images of another */
        *org = 0;
        *span = b->L[k];
    } else {
        *org = r_valid + wall;
        *span = b->L[k] - 2 * *org;
        if (!(*span > 0))
            return 0;
    }
    double c = ceil(*span / e);
    if (!(c < (double)MAX_VOXELS))
        return 0;
    *n = c < 1 ? 1 : (int64_t)c;
    return 1;
}

uint64_t pk_rsa_vox_count(const pk_box *b, double r_valid, double r_top, double gap, double wall)
{
    if (!b || b->dim < 2 || b->dim > 3 || !(r_valid > 0) || !(r_top >= r_valid) || !(gap >= 0) ||
        !(wall >= 0))
        return 0;
    uint64_t total = 1;
    for (int k = 0; k < b->dim; k++) {
        double org, span;
        int64_t n;
        if (!axis_lattice(b, k, r_valid, r_top, gap, wall, &org, &span, &n))
            return 0;
        if (total > MAX_VOXELS / (uint64_t)n)
            return UINT64_MAX;
        total *= (uint64_t)n;
    }
    return total;
}

int pk_rsa_vox_init(pk_rsa_vox *v, const pk_box *b, double r_valid, double r_top, double gap,
                    double wall)
{
    memset(v, 0, sizeof *v);
    uint64_t nv = pk_rsa_vox_count(b, r_valid, r_top, gap, wall);
    if (nv == 0 || nv >= MAX_VOXELS)
        return -1;
    v->box = *b;
    v->r_valid = r_valid;
    v->r_top = r_top;
    v->gap = gap;
    double lmax = 0;
    for (int k = 0; k < PK_MAXDIM; k++) {
        v->n[k] = 1;
        v->e[k] = v->inv_e[k] = 1;
        if (k >= b->dim)
            continue;
        double span;
        axis_lattice(b, k, r_valid, r_top, gap, wall, &v->org[k], &span, &v->n[k]);
        v->e[k] = span / (double)v->n[k];
        v->inv_e[k] = 1 / v->e[k];
        lmax = fmax(lmax, b->L[k]);
    }
    /* Round-off guard of the cover test: far above double rounding of the
     * coordinates, far below any length that matters to the statistics. */
    v->margin = 1e-9 * (2 * r_top + gap) + 1e-12 * lmax;
    v->nvox = nv;
    v->sub = b->dim == 3 ? 4 : 8; /* 4³ or 8² sub-voxels: one 64-bit mask */
    for (int k = 0; k < PK_MAXDIM; k++)
        v->se[k] = v->e[k] / (double)v->sub;
    v->cell = malloc(nv * sizeof *v->cell);
    v->slot = malloc(nv * sizeof *v->slot);
    v->active = malloc(nv * sizeof *v->active);
    if (!v->cell || !v->slot || !v->active) {
        pk_rsa_vox_free(v);
        return -1;
    }
    for (uint64_t i = 0; i < nv; i++) {
        v->cell[i] = (pk_rsa_cell){.x = {INFINITY, 0, 0}, .r = 0, .mask = ~(uint64_t)0};
        v->slot[i] = (uint32_t)i;
        v->active[i] = (uint32_t)i;
    }
    v->nactive = nv;
    return 0;
}

void pk_rsa_vox_free(pk_rsa_vox *v)
{
    free(v->cell);
    free(v->slot);
    free(v->active);
    memset(v, 0, sizeof *v);
}

/* Periodic image of an unwrapped index: the ranges scanned here reach at most
 * one period beyond the lattice (reach < L/2), so no division is needed. */
static inline int64_t image_of(int64_t i, int64_t n) { return i < 0 ? -1 : (i >= n ? 1 : 0); }

/* Index range [*lo, *hi] of voxels along axis k meeting [a, c]; walled axes
 * are clipped to the lattice, periodic ones stay unwrapped. */
static inline void axis_range(const pk_rsa_vox *v, int k, double a, double c, int64_t *lo,
                              int64_t *hi)
{
    *lo = (int64_t)floor((a - v->org[k]) * v->inv_e[k]);
    *hi = (int64_t)floor((c - v->org[k]) * v->inv_e[k]);
    if (!v->box.periodic[k]) {
        if (*lo < 0)
            *lo = 0;
        if (*hi > v->n[k] - 1)
            *hi = v->n[k] - 1;
    }
}

static inline void remove_voxel(pk_rsa_vox *v, uint64_t vid)
{
    uint32_t s = v->slot[vid];
    if (s == NO_SLOT)
        return;
    uint32_t last = v->active[--v->nactive];
    v->active[s] = last;
    v->slot[last] = s;
    v->slot[vid] = NO_SLOT;
}

/* Squared distance from c to the nearest point of voxel interval i on axis k. */
static inline double near2(const pk_rsa_vox *v, int k, int64_t i, double c)
{
    double a = v->org[k] + v->e[k] * (double)i;
    double f = c < a ? a - c : (c > a + v->e[k] ? c - a - v->e[k] : 0);
    return f * f;
}

static inline int64_t wrap_index(const pk_rsa_vox *v, int k, int64_t i)
{
    if (!v->box.periodic[k] || (i >= 0 && i < v->n[k]))
        return i;
    int64_t w = i % v->n[k];
    return w < 0 ? w + v->n[k] : w;
}

/* Squared distances from c to the farthest points of the `sub` sub-intervals
 * of voxel interval i on axis k (f[l] for sub-interval l). */
static inline void sub_far2(const pk_rsa_vox *v, int k, int64_t i, double c, double *f)
{
    for (int l = 0; l < v->sub; l++) {
        double a = v->org[k] + v->se[k] * (double)(i * v->sub + l);
        double d = c < a + 0.5 * v->se[k] ? a + v->se[k] - c : c - a;
        f[l] = d * d;
    }
}

/* A sub-voxel is marked covered when its farthest corner is inside the ball:
 * the ball is convex, so the whole sub-voxel is, and every point in it is
 * closer than r + r_valid + Δd <= r + r' + Δd to the grain, for every
 * r' >= r_valid: the exact test would reject it.  The radius is shrunk by
 * `margin` so round-off never marks a sub-voxel holding an acceptable point. */
void pk_rsa_vox_cover(pk_rsa_vox *v, const double x[PK_MAXDIM], double r)
{
    double R = r + v->r_valid + v->gap - v->margin;
    if (!(R > 0))
        return;
    const double R2 = R * R;
    const int dim = v->box.dim, S = v->sub, Sz = dim == 3 ? v->sub : 1;
    int64_t zlo = 0, zhi = 0, ylo, yhi, xlo, xhi;
    if (dim == 3)
        axis_range(v, 2, x[2] - R, x[2] + R, &zlo, &zhi);
    axis_range(v, 1, x[1] - R, x[1] + R, &ylo, &yhi);
    axis_range(v, 0, x[0] - R, x[0] + R, &xlo, &xhi);
    double fz[8] = {0}, fy[8], fx[8];
    for (int64_t iz = zlo; iz <= zhi; iz++) {
        double nz = dim == 3 ? near2(v, 2, iz, x[2]) : 0;
        if (nz >= R2)
            continue;
        if (dim == 3)
            sub_far2(v, 2, iz, x[2], fz);
        uint64_t zbase = (uint64_t)wrap_index(v, 2, iz) * (uint64_t)v->n[1];
        for (int64_t iy = ylo; iy <= yhi; iy++) {
            double nzy = nz + near2(v, 1, iy, x[1]);
            if (nzy >= R2)
                continue;
            sub_far2(v, 1, iy, x[1], fy);
            uint64_t base = (zbase + (uint64_t)wrap_index(v, 1, iy)) * (uint64_t)v->n[0];
            for (int64_t ix = xlo; ix <= xhi; ix++) {
                if (nzy + near2(v, 0, ix, x[0]) >= R2)
                    continue;
                uint64_t vid = base + (uint64_t)wrap_index(v, 0, ix);
                uint64_t m = v->cell[vid].mask;
                if (!m)
                    continue;
                sub_far2(v, 0, ix, x[0], fx);
                uint64_t covered = 0;
                unsigned bit = 0; /* (lz·S + ly)·S + lx, as in pk_rsa_vox_draw */
                for (int lz = 0; lz < Sz; lz++)
                    for (int ly = 0; ly < S; ly++) {
                        double rem = R2 - fz[lz] - fy[ly];
                        for (int lx = 0; lx < S; lx++, bit++)
                            covered |= (uint64_t)(fx[lx] <= rem) << bit;
                    }
                if (m & covered) {
                    v->cell[vid].mask = m & ~covered;
                    if (!v->cell[vid].mask)
                        remove_voxel(v, vid);
                }
            }
        }
    }
}

/* Uniform integer in [0, n), n < 2^32, without bias (Lemire's method). */
static inline uint64_t uniform_below(pk_rng *g, uint32_t n)
{
    uint64_t m = (pk_rng_next(g) >> 32) * (uint64_t)n;
    uint32_t l = (uint32_t)m;
    if (l < n) {
        uint32_t t = (uint32_t)(0u - n) % n;
        while (l < t) {
            m = (pk_rng_next(g) >> 32) * (uint64_t)n;
            l = (uint32_t)m;
        }
    }
    return m >> 32;
}

int pk_rsa_vox_draw(const pk_rsa_vox *v, pk_rng *g, double x[PK_MAXDIM], uint64_t *vid)
{
    if (v->nactive == 0)
        return -1;
    uint64_t id = v->active[uniform_below(g, (uint32_t)v->nactive)];
    *vid = id;
    unsigned bit = (unsigned)(pk_rng_next(g) >> 58); /* uniform sub-voxel of 64 */
    if (!(v->cell[id].mask >> bit & 1))
        return 1; /* covered sub-voxel: the exact test would reject any point in it */
    uint64_t t = id;
    x[2] = 0;
    for (int k = 0; k < v->box.dim; k++) {
        int64_t i = (int64_t)(t % (uint64_t)v->n[k]);
        t /= (uint64_t)v->n[k];
        int64_t j = i * v->sub + (int64_t)(bit % (unsigned)v->sub);
        bit /= (unsigned)v->sub;
        x[k] = v->org[k] + v->se[k] * ((double)j + pk_rng_uniform(g));
    }
    return 0;
}

int pk_rsa_vox_overlaps(const pk_rsa_vox *v, const double x[PK_MAXDIM], double r)
{
    const int dim = v->box.dim;
    const double reach = r + v->r_top + v->gap + v->margin, reach2 = reach * reach;
    int64_t zlo = 0, zhi = 0, ylo, yhi;
    if (dim == 3)
        axis_range(v, 2, x[2] - reach, x[2] + reach, &zlo, &zhi);
    axis_range(v, 1, x[1] - reach, x[1] + reach, &ylo, &yhi);
    const double L0 = v->box.L[0], L1 = v->box.L[1], L2 = v->box.L[2];
    for (int64_t iz = zlo; iz <= zhi; iz++) {
        double dz2 = dim == 3 ? near2(v, 2, iz, x[2]) : 0;
        if (dz2 >= reach2)
            continue;
        int64_t wz = wrap_index(v, 2, iz);
        double sz = dim == 3 && v->box.periodic[2] ? L2 * (double)image_of(iz, v->n[2]) : 0;
        uint64_t zbase = (uint64_t)wz * (uint64_t)v->n[1];
        for (int64_t iy = ylo; iy <= yhi; iy++) {
            double rem = reach2 - dz2 - near2(v, 1, iy, x[1]);
            if (rem <= 0)
                continue;
            double w = sqrt(rem);
            int64_t xlo, xhi;
            axis_range(v, 0, x[0] - w, x[0] + w, &xlo, &xhi);
            double sy = v->box.periodic[1] ? L1 * (double)image_of(iy, v->n[1]) : 0;
            uint64_t base = (zbase + (uint64_t)wrap_index(v, 1, iy)) * (uint64_t)v->n[0];
            const double py = x[1] - sy, pz = x[2] - sz;
            for (int64_t ix = xlo; ix <= xhi; ix++) {
                double sx = v->box.periodic[0] ? L0 * (double)image_of(ix, v->n[0]) : 0;
                const pk_rsa_cell *cj = &v->cell[base + (uint64_t)wrap_index(v, 0, ix)];
                /* empty voxel: x[0] = +inf, so d2 = +inf never counts */
                double d0 = cj->x[0] - (x[0] - sx), d1 = cj->x[1] - py, d2 = cj->x[2] - pz;
                double s = r + cj->r + v->gap;
                if (d0 * d0 + d1 * d1 + d2 * d2 < s * s)
                    return 1;
            }
        }
    }
    return 0;
}

int pk_rsa_vox_store(pk_rsa_vox *v, uint64_t vid, const double x[PK_MAXDIM], double r)
{
    if (vid >= v->nvox || v->cell[vid].x[0] != INFINITY)
        return -1;
    pk_rsa_cell *c = &v->cell[vid];
    c->x[0] = x[0];
    c->x[1] = x[1];
    c->x[2] = v->box.dim == 3 ? x[2] : 0;
    c->r = r;
    if (r > v->r_top)
        v->r_top = r;
    return 0;
}
