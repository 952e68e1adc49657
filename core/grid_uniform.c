/* grid_uniform.c — levels of dense cell lists (see grid_uniform.h). */
#include "grid_uniform.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int level_of(const pk_ugrid *g, double r)
{
    if (!(r > 0))
        return g->nlevel - 1;
    double l = floor(log2(g->r_top / r));
    return l < 0 ? 0 : l >= g->nlevel ? g->nlevel - 1 : (int)l;
}

/* Cells of edge >= 2 r_hi per axis, at most max_cells in all. */
static int level_init(pk_ugrid_level *lv, const pk_box *b, double r_hi, double max_cells)
{
    double want = 2 * r_hi, ncell;
    for (;;) {
        ncell = 1;
        for (int k = 0; k < b->dim; k++)
            ncell *= fmax(1, floor(b->L[k] / want));
        if (ncell <= max_cells)
            break;
        want *= 1.25;
    }
    for (int k = 0; k < PK_MAXDIM; k++) {
        lv->n[k] = k < b->dim ? (int32_t)fmax(1, floor(b->L[k] / want)) : 1;
        lv->inv_h[k] = k < b->dim ? lv->n[k] / b->L[k] : 1;
    }
    lv->head = malloc((size_t)ncell * sizeof *lv->head);
    if (!lv->head)
        return -1;
    memset(lv->head, 0xff, (size_t)ncell * sizeof *lv->head);
    return 0;
}

int pk_ugrid_init(pk_ugrid *g, const pk_box *b, const double *r, size_t n, size_t cap)
{
    memset(g, 0, sizeof *g);
    if (!b || b->dim < 2 || b->dim > 3 || cap < n || cap > INT32_MAX)
        return -1;
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < n; i++)
        if (r[i] > 0) {
            lo = fmin(lo, r[i]);
            hi = fmax(hi, r[i]);
        }
    if (!(hi > 0))
        return -1;
    g->box = *b;
    for (int k = 0; k < b->dim; k++)
        if (b->periodic[k]) {
            g->L[k] = b->L[k];
            g->inv_L[k] = 1 / b->L[k];
        }
    g->r_top = hi * (1 + 1e-12);
    int nl = 1 + (int)floor(log2(hi / lo));
    g->nlevel = nl < PK_UGRID_MAX_LEVELS ? nl : PK_UGRID_MAX_LEVELS;
    size_t count[PK_UGRID_MAX_LEVELS] = {0};
    for (size_t i = 0; i < n; i++)
        count[level_of(g, r[i])]++;
    g->cap = cap ? cap : 1;
    g->next = malloc(g->cap * sizeof *g->next);
    g->prev = malloc(g->cap * sizeof *g->prev);
    g->cell = malloc(g->cap * sizeof *g->cell);
    g->level = malloc(g->cap * sizeof *g->level);
    if (!g->next || !g->prev || !g->cell || !g->level) {
        pk_ugrid_free(g);
        return -1;
    }
    memset(g->cell, 0xff, g->cap * sizeof *g->cell);
    for (int l = 0; l < g->nlevel; l++)
        if (level_init(&g->lv[l], b, ldexp(g->r_top, -l),
                       PK_UGRID_CELLS_PER_GRAIN * (double)count[l] + 64) != 0) {
            pk_ugrid_free(g);
            return -1;
        }
    return 0;
}

void pk_ugrid_free(pk_ugrid *g)
{
    for (int l = 0; l < PK_UGRID_MAX_LEVELS; l++)
        free(g->lv[l].head);
    free(g->next);
    free(g->prev);
    free(g->cell);
    free(g->level);
    memset(g, 0, sizeof *g);
}

/* Cell coordinate along k, clamped (round-off at L, grains off a wall). */
static inline int32_t coord(const pk_ugrid_level *lv, int k, double xk)
{
    double c = floor(xk * lv->inv_h[k]);
    return c < 0 ? 0 : c >= lv->n[k] ? lv->n[k] - 1 : (int32_t)c;
}

int pk_ugrid_insert(pk_ugrid *g, const pk_particles *p, size_t i)
{
    if (i >= g->cap)
        return -1;
    pk_ugrid_remove(g, i);
    int l = level_of(g, p->r[i]);
    pk_ugrid_level *lv = &g->lv[l];
    const double *x = &p->x[3 * i];
    int32_t c = 0;
    for (int k = PK_MAXDIM - 1; k >= 0; k--)
        c = c * lv->n[k] + (k < g->box.dim ? coord(lv, k, x[k]) : 0);
    int32_t h = lv->head[c];
    g->next[i] = h;
    g->prev[i] = -1;
    if (h >= 0)
        g->prev[h] = (int32_t)i;
    lv->head[c] = (int32_t)i;
    g->cell[i] = c;
    g->level[i] = (int8_t)l;
    if (p->r[i] > lv->r_max)
        lv->r_max = p->r[i];
    return 0;
}

void pk_ugrid_remove(pk_ugrid *g, size_t i)
{
    if (i >= g->cap || g->cell[i] < 0)
        return;
    int32_t nx = g->next[i], pv = g->prev[i];
    if (pv >= 0)
        g->next[pv] = nx;
    else
        g->lv[g->level[i]].head[g->cell[i]] = nx;
    if (nx >= 0)
        g->prev[nx] = pv;
    g->cell[i] = -1;
}

static inline int32_t wrap_index(int64_t c, int32_t n)
{
    int64_t m = c % n;
    return (int32_t)(m < 0 ? m + n : m);
}

static int query_level(const pk_ugrid *g, const pk_ugrid_level *lv, const pk_particles *p,
                       const double x[PK_MAXDIM], double r, pk_grid_visit fn, void *ctx)
{
    /* margin: a grain within round-off of a cell face may be filed in the
     * neighbouring cell of its periodic image */
    const double reach = (r + lv->r_max) * (1 + 1e-9);
    int64_t lo[PK_MAXDIM] = {0, 0, 0}, hi[PK_MAXDIM] = {0, 0, 0};
    for (int k = 0; k < g->box.dim; k++) {
        const int32_t n = lv->n[k];
        const double m = 1e-9 * n; /* cells of round-off margin, see above */
        double flo = floor((x[k] - reach) * lv->inv_h[k] - m);
        double fhi = floor((x[k] + reach) * lv->inv_h[k] + m);
        if (g->box.periodic[k]) {
            if (fhi - flo + 1 >= n) { /* the whole axis, each cell once */
                flo = 0;
                fhi = n - 1;
            }
        } else {
            flo = fmax(flo, 0);
            fhi = fmin(fhi, n - 1);
        }
        lo[k] = (int64_t)flo;
        hi[k] = (int64_t)fhi;
    }
    const double *X = p->x, *R = p->r;
    const double M = 6755399441055744.0; /* round-to-nearest trick of pk_min_image3 */
    const double L0 = g->L[0], L1 = g->L[1], L2 = g->L[2];
    const double iL0 = g->inv_L[0], iL1 = g->inv_L[1], iL2 = g->inv_L[2];
    const double x0 = x[0], x1 = x[1], x2 = x[2];
    const int32_t nx = lv->n[0], ix0 = wrap_index(lo[0], nx);
    for (int64_t cz = lo[2]; cz <= hi[2]; cz++) {
        const int32_t iz = wrap_index(cz, lv->n[2]);
        for (int64_t cy = lo[1]; cy <= hi[1]; cy++) {
            const int32_t *row = &lv->head[(iz * lv->n[1] + wrap_index(cy, lv->n[1])) * nx];
            int32_t ix = ix0;
            for (int64_t cx = lo[0]; cx <= hi[0]; cx++, ix = ix + 1 == nx ? 0 : ix + 1) {
                for (int32_t j = row[ix]; j >= 0; j = g->next[j]) {
                    const double *xj = &X[3 * (size_t)j];
                    double d0 = xj[0] - x0, d1 = xj[1] - x1, d2 = xj[2] - x2;
                    d0 -= L0 * ((d0 * iL0 + M) - M);
                    d1 -= L1 * ((d1 * iL1 + M) - M);
                    d2 -= L2 * ((d2 * iL2 + M) - M);
                    const double dd = d0 * d0 + d1 * d1 + d2 * d2;
                    const double sr = r + R[j];
                    if (dd < sr * sr) {
                        const double d[PK_MAXDIM] = {d0, d1, d2};
                        int stop = fn((size_t)j, d, dd, ctx);
                        if (stop)
                            return stop;
                    }
                }
            }
        }
    }
    return 0;
}

int pk_ugrid_query(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                   pk_grid_visit fn, void *ctx)
{
    for (int l = 0; l < g->nlevel; l++) {
        if (!(g->lv[l].r_max > 0))
            continue; /* nothing registered yet */
        int stop = query_level(g, &g->lv[l], p, x, r, fn, ctx);
        if (stop)
            return stop;
    }
    return 0;
}
