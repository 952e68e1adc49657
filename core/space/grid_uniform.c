/* grid_uniform.c — levels of dense cell lists for often rebuilt neighbour
 * searches (EDMD's lists).  Contract: core/space/grid_uniform.h. */
#include "grid_uniform.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grid_cover.h"
#include "grid_uniform_cells.h"

/* floor(log2(r_top / r)) clamped to the levels, by halving (exact in binary
 * floating point, no libm call: an insert per list rebuild). */
static int level_of(const pk_ugrid *g, double r)
{
    if (!(r > 0))
        return g->nlevel - 1;
    int l = 0;
    for (double bound = 0.5 * g->r_top; l + 1 < g->nlevel && r <= bound; bound *= 0.5)
        l++;
    return l;
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
    if (pk_ugrid_cover_init(g, count, n) != 0) {
        pk_ugrid_free(g);
        return -1;
    }
    return 0;
}

void pk_ugrid_free(pk_ugrid *g)
{
    pk_ugrid_cover_free(g);
    for (int l = 0; l < PK_UGRID_MAX_LEVELS; l++)
        free(g->lv[l].head);
    free(g->next);
    free(g->prev);
    free(g->cell);
    free(g->level);
    memset(g, 0, sizeof *g);
}

/* i out of its cell's chain (registered). */
static void unlink_grain(pk_ugrid *g, size_t i)
{
    int32_t nx = g->next[i], pv = g->prev[i];
    /* the chain is doubly linked: i's neighbours point back at i */
    assert(pv < 0 ? g->lv[g->level[i]].head[g->cell[i]] == (int32_t)i : g->next[pv] == (int32_t)i);
    assert(nx < 0 || g->prev[nx] == (int32_t)i);
    if (pv >= 0)
        g->next[pv] = nx;
    else
        g->lv[g->level[i]].head[g->cell[i]] = nx;
    if (nx >= 0)
        g->prev[nx] = pv;
    g->cell[i] = -1;
}

int pk_ugrid_insert(pk_ugrid *g, const pk_particles *p, size_t i)
{
    if (i >= g->cap)
        return -1;
    int l = level_of(g, p->r[i]);
    /* a grain re-filed in its covered level: its cover cells are moved
     * (pk_ugrid_cover_move), not walked out and in again */
    const int move = g->covered[l] && g->cell[i] >= 0 && g->level[i] == l;
    if (move)
        unlink_grain(g, i);
    else
        pk_ugrid_remove(g, i);
    pk_ugrid_level *lv = &g->lv[l];
    const double *x = &p->x[3 * i];
    int32_t c = 0;
    for (int k = PK_MAXDIM - 1; k >= 0; k--)
        c = c * lv->n[k] + (k < g->box.dim ? ug_coord(lv, k, x[k]) : 0);
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
    assert(c >= 0 && p->r[i] <= lv->r_max); /* a query reaches it through r_max */
    if (g->covered[l] &&
        (move ? pk_ugrid_cover_move(g, i, x, p->r[i]) : pk_ugrid_cover_add(g, i, x, p->r[i])) != 0)
        return -1;
    return 0;
}

void pk_ugrid_remove(pk_ugrid *g, size_t i)
{
    if (i >= g->cap || g->cell[i] < 0)
        return;
    if (g->cov_ball)
        pk_ugrid_cover_remove(g, i);
    unlink_grain(g, i);
}

/* Query context of one level: the point, the radius and the box. */
typedef struct qctx {
    const int32_t *next;
    const double *X, *R;
    double x0, x1, x2, r;
    double L0, L1, L2, iL0, iL1, iL2;
    pk_grid_visit fn;
    void *ctx;
} qctx;

/* Cells [a, b) of one row.  images = 0 when the query box lies inside the
 * periodic cell range without wrapping: then every grain within reach is
 * within reach by its stored position (an image x_j ± L is outside [0, L),
 * hence outside the box), and the minimum image of those differences is the
 * difference itself (round(d/L) = 0), so it is skipped. */
static inline int scan_cells(const qctx *q, const int32_t *row, int32_t a, int32_t b,
                             const int images)
{
    const double M = 6755399441055744.0; /* round-to-nearest trick of pk_min_image3 */
    for (int32_t c = a; c < b; c++)
        for (int32_t j = row[c]; j >= 0; j = q->next[j]) {
            const double *xj = &q->X[3 * (size_t)j];
            double d0 = xj[0] - q->x0, d1 = xj[1] - q->x1, d2 = xj[2] - q->x2;
            if (images) {
                d0 -= q->L0 * ((d0 * q->iL0 + M) - M);
                d1 -= q->L1 * ((d1 * q->iL1 + M) - M);
                d2 -= q->L2 * ((d2 * q->iL2 + M) - M);
            }
            const double dd = d0 * d0 + d1 * d1 + d2 * d2;
            const double sr = q->r + q->R[j];
            if (dd < sr * sr) {
                const double d[PK_MAXDIM] = {d0, d1, d2};
                int stop = q->fn((size_t)j, d, dd, q->ctx);
                if (stop)
                    return stop;
            }
        }
    return 0;
}

/* One level: every cell of the box [x − reach, x + reach] (the variants
 * tried against it — culled rows, finer cells, packed copies — are in
 * docs/perf/space.md). */
static int query_level(const pk_ugrid *g, const pk_ugrid_level *lv, const pk_particles *p,
                       const double x[PK_MAXDIM], double r, pk_grid_visit fn, void *ctx)
{
    /* margin: a grain within round-off of a cell face may be filed in the
     * neighbouring cell of its periodic image */
    const double reach = (r + lv->r_max) * (1 + 1e-9);
    int32_t lo[PK_MAXDIM] = {0, 0, 0}, cnt[PK_MAXDIM] = {1, 1, 1};
    int images = 0; /* some periodic axis wraps or is covered whole */
    for (int k = 0; k < g->box.dim; k++) {
        const int32_t n = lv->n[k];
        const double m = 1e-9 * n; /* cells of round-off margin, see above */
        double flo = ug_fast_floor((x[k] - reach) * lv->inv_h[k] - m);
        double fhi = ug_fast_floor((x[k] + reach) * lv->inv_h[k] + m);
        if (g->box.periodic[k]) {
            if (fhi - flo + 1 >= n) { /* the whole axis, each cell once */
                flo = 0;
                fhi = n - 1;
                images = 1;
            } else if (flo < 0 || fhi > n - 1) {
                images = 1;
            }
        } else {
            flo = flo > 0 ? flo : 0;
            fhi = fhi < n - 1 ? fhi : n - 1;
        }
        /* first cell (wrapped once: the modulo stays out of the loops) and count */
        lo[k] = ug_wrap_index((int64_t)flo, n);
        cnt[k] = (int32_t)(fhi - flo) + 1;
    }
    const qctx q = {g->next, p->x,    p->r,        x[0],        x[1],        x[2], r,  g->L[0],
                    g->L[1], g->L[2], g->inv_L[0], g->inv_L[1], g->inv_L[2], fn,   ctx};
    const int32_t nx = lv->n[0], ny = lv->n[1], nz = lv->n[2];
    /* x cells: [lo, e1) then, past the periodic seam, [0, e2) */
    const int32_t e1 = lo[0] + cnt[0] <= nx ? lo[0] + cnt[0] : nx, e2 = lo[0] + cnt[0] - e1;
    int32_t iz = lo[2];
    for (int32_t cz = 0; cz < cnt[2]; cz++, iz = iz + 1 == nz ? 0 : iz + 1) {
        int32_t iy = lo[1];
        for (int32_t cy = 0; cy < cnt[1]; cy++, iy = iy + 1 == ny ? 0 : iy + 1) {
            const int32_t *row = &lv->head[((size_t)iz * (size_t)ny + (size_t)iy) * (size_t)nx];
            int stop =
                images ? scan_cells(&q, row, lo[0], e1, 1) : scan_cells(&q, row, lo[0], e1, 0);
            if (!stop && e2 > 0)
                stop = scan_cells(&q, row, 0, e2, 1);
            if (stop)
                return stop;
        }
    }
    return 0;
}

int pk_ugrid_query(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                   pk_grid_visit fn, void *ctx)
{
    const int cover = g->cov && r <= g->cov_r;
    if (cover) {
        int stop = pk_ugrid_cover_query(g, p, x, r, fn, ctx);
        if (stop)
            return stop;
    }
    for (int l = 0; l < g->nlevel; l++) {
        if (cover && g->covered[l])
            continue;
        if (!(g->lv[l].r_max > 0))
            continue; /* nothing registered yet */
        int stop = query_level(g, &g->lv[l], p, x, r, fn, ctx);
        if (stop)
            return stop;
    }
    return 0;
}
