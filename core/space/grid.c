/* grid.c — the hashed multi-level cell grid: O(1) neighbour queries for any
 * size ratio, memory O(N).  Contract: core/space/grid.h. */
#include "grid.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CELLS_PER_AXIS ((int64_t)1 << 20)
/* A level whose cells number at most this many per grain (plus a constant)
 * gets one head per cell instead of hashed buckets: a cell visit is one load,
 * with no other cells' grains to walk past (that walk was ~40 % of RSA's
 * overlap test at A16 Δd 1 mm; docs/perf/rsa-gap.md). */
#define DENSE_CELLS_PER_GRAIN 4
#define DENSE_CELLS_FREE 4096

static uint64_t next_pow2(uint64_t v)
{
    uint64_t p = 16;
    while (p < v)
        p <<= 1;
    return p;
}

static int level_of(const pk_grid *g, double r)
{
    if (!(r > 0))
        return g->nlevel - 1;
    int l = (int)floor(log2(g->r_top / r));
    if (l < 0)
        l = 0;
    if (l >= g->nlevel)
        l = g->nlevel - 1;
    return l;
}

static int grid_init(pk_grid *g, const pk_box *b, double r_min, double r_max, double gap,
                     size_t cap, int dense_ok)
{
    memset(g, 0, sizeof *g);
    if (!b || !(r_max > 0) || !(gap >= 0) || !(r_min >= 0) || b->dim < 2 || b->dim > 3)
        return -1;
    if (!(r_min > 0) || r_min > r_max)
        r_min = r_max;
    g->box = *b;
    g->gap = gap;
    g->r_top = r_max * (1 + 1e-12);
    int nl = 1 + (int)floor(log2(r_max / r_min));
    g->nlevel = nl < PK_GRID_MAX_LEVELS ? nl : PK_GRID_MAX_LEVELS;
    for (int l = 0; l < g->nlevel; l++) {
        pk_grid_level *lv = &g->lv[l];
        lv->r_hi = ldexp(g->r_top, -l);
        /* the finest level also takes anything smaller than its lower bound */
        double want = 2 * lv->r_hi + gap;
        for (int k = 0; k < PK_MAXDIM; k++) {
            if (k >= b->dim) {
                lv->ncell[k] = 1;
                lv->h[k] = 1;
                continue;
            }
            double L = b->L[k];
            int64_t n = b->periodic[k] ? (int64_t)floor(L / want) : (int64_t)ceil(L / want);
            if (n < 1)
                n = 1;
            if (n > MAX_CELLS_PER_AXIS)
                n = MAX_CELLS_PER_AXIS;
            lv->ncell[k] = n;
            lv->h[k] = b->periodic[k] ? L / (double)n : fmax(want, L / (double)n);
        }
    }
    g->cap = cap ? cap : 1;
    for (int l = 0; l < g->nlevel; l++) {
        pk_grid_level *lv = &g->lv[l];
        double cells = (double)lv->ncell[0] * (double)lv->ncell[1] * (double)lv->ncell[2];
        lv->dense =
            dense_ok && cells <= (double)DENSE_CELLS_PER_GRAIN * (double)g->cap + DENSE_CELLS_FREE;
        uint64_t nb = lv->dense ? (uint64_t)cells : 16;
        lv->mask = nb - 1;
        lv->head = malloc(nb * sizeof *lv->head);
        if (!lv->head) {
            pk_grid_free(g);
            return -1;
        }
        memset(lv->head, 0xff, nb * sizeof *lv->head);
    }
    g->next = malloc(g->cap * sizeof *g->next);
    g->cell = malloc(g->cap * sizeof *g->cell);
    g->level = malloc(g->cap * sizeof *g->level);
    if (!g->next || !g->cell || !g->level) {
        pk_grid_free(g);
        return -1;
    }
    memset(g->level, 0xff, g->cap * sizeof *g->level);
    return 0;
}

int pk_grid_init(pk_grid *g, const pk_box *b, double r_min, double r_max, double gap, size_t cap)
{
    return grid_init(g, b, r_min, r_max, gap, cap, 0);
}

int pk_grid_init_dense(pk_grid *g, const pk_box *b, double r_min, double r_max, double gap,
                       size_t cap)
{
    return grid_init(g, b, r_min, r_max, gap, cap, 1);
}

void pk_grid_free(pk_grid *g)
{
    for (int l = 0; l < PK_GRID_MAX_LEVELS; l++)
        free(g->lv[l].head);
    free(g->next);
    free(g->cell);
    free(g->level);
    memset(g, 0, sizeof *g);
}

static inline uint64_t bucket_of(const pk_grid_level *lv, uint64_t lin)
{
    if (lv->dense)
        return lin;
    /* Fibonacci hashing: neighbouring cells land in unrelated buckets. */
    return (lin * 0x9E3779B97F4A7C15ull) >> 17 & lv->mask;
}

static inline int64_t cell_coord(const pk_grid *g, const pk_grid_level *lv, int k, double xk)
{
    int64_t c = (int64_t)floor(xk / lv->h[k]);
    int64_t n = lv->ncell[k];
    if (g->box.periodic[k]) {
        c %= n;
        if (c < 0)
            c += n;
    } else if (c < 0) {
        c = 0;
    } else if (c >= n) {
        c = n - 1;
    }
    assert(c >= 0 && c < n);
    return c;
}

static uint64_t cell_of(const pk_grid *g, const pk_grid_level *lv, const double *x)
{
    uint64_t lin = 0;
    for (int k = g->box.dim - 1; k >= 0; k--)
        lin = lin * (uint64_t)lv->ncell[k] + (uint64_t)cell_coord(g, lv, k, x[k]);
    return lin;
}

static void link_grain(pk_grid_level *lv, pk_grid *g, size_t i)
{
    uint64_t bkt = bucket_of(lv, g->cell[i]);
    g->next[i] = lv->head[bkt];
    lv->head[bkt] = (int32_t)i;
}

/* Double the bucket table of a level when it holds more grains than buckets. */
static int grow_level(pk_grid *g, pk_grid_level *lv)
{
    uint64_t nb = next_pow2(2 * (lv->mask + 1));
    int32_t *old = lv->head;
    uint64_t old_n = lv->mask + 1;
    int32_t *head = malloc(nb * sizeof *head);
    if (!head)
        return -1;
    memset(head, 0xff, nb * sizeof *head);
    lv->head = head;
    lv->mask = nb - 1;
    for (uint64_t b = 0; b < old_n; b++) {
        int32_t j = old[b];
        while (j >= 0) {
            int32_t nx = g->next[j];
            link_grain(lv, g, (size_t)j);
            j = nx;
        }
    }
    free(old);
    return 0;
}

int pk_grid_insert(pk_grid *g, const pk_particles *p, size_t i)
{
    if (i >= g->cap || i > INT32_MAX)
        return -1;
    if (g->level[i] >= 0)
        pk_grid_remove(g, i);
    int l = level_of(g, p->r[i]);
    pk_grid_level *lv = &g->lv[l];
    if (!lv->dense && lv->count + 1 > lv->mask + 1 && grow_level(g, lv) != 0)
        return -1;
    g->level[i] = (int8_t)l;
    /* A grain larger than the range given at init (a growing grain) lands in
     * level 0; its bound grows with it so queries still reach it. */
    if (p->r[i] > lv->r_hi)
        lv->r_hi = p->r[i];
    g->cell[i] = cell_of(g, lv, &p->x[3 * i]);
    link_grain(lv, g, i);
    lv->count++;
    /* queries reach a level's grains through its bound; buckets >= grains */
    assert(p->r[i] <= lv->r_hi && (lv->dense || lv->count <= lv->mask + 1));
    return 0;
}

void pk_grid_remove(pk_grid *g, size_t i)
{
    if (i >= g->cap || g->level[i] < 0)
        return;
    pk_grid_level *lv = &g->lv[g->level[i]];
    int32_t *pp = &lv->head[bucket_of(lv, g->cell[i])];
    while (*pp >= 0 && *pp != (int32_t)i)
        pp = &g->next[*pp];
    assert(*pp == (int32_t)i); /* a filed grain is in its bucket's chain */
    if (*pp == (int32_t)i) {
        *pp = g->next[i];
        lv->count--;
    }
    g->level[i] = -1;
}

int pk_grid_update(pk_grid *g, const pk_particles *p, size_t i)
{
    if (i < g->cap && g->level[i] >= 0) {
        int l = level_of(g, p->r[i]);
        if (l == g->level[i] && cell_of(g, &g->lv[l], &p->x[3 * i]) == g->cell[i]) {
            /* same cell, but a grown grain must still raise its level's bound */
            if (p->r[i] > g->lv[l].r_hi)
                g->lv[l].r_hi = p->r[i];
            return 0;
        }
    }
    return pk_grid_insert(g, p, i);
}

/* The one cell scan behind both queries.  With fn == NULL it is the RSA
 * overlap test (extra = 0, stop at the first grain closer than contact). */
static inline int scan(const pk_grid *g, const pk_particles *p, const double *x, double r,
                       double extra, pk_grid_visit fn, void *ctx)
{
    const int dim = g->box.dim;
    for (int l = 0; l < g->nlevel; l++) {
        const pk_grid_level *lv = &g->lv[l];
        if (lv->count == 0)
            continue;
        double reach = r + lv->r_hi + g->gap + extra;
        int64_t lo[PK_MAXDIM] = {0, 0, 0}, hi[PK_MAXDIM] = {0, 0, 0};
        int wrap[PK_MAXDIM] = {0, 0, 0};
        for (int k = 0; k < dim; k++) {
            int64_t n = lv->ncell[k];
            lo[k] = (int64_t)floor((x[k] - reach) / lv->h[k]);
            hi[k] = (int64_t)floor((x[k] + reach) / lv->h[k]);
            if (g->box.periodic[k]) {
                if (hi[k] - lo[k] + 1 >= n) {
                    lo[k] = 0;
                    hi[k] = n - 1;
                } else {
                    wrap[k] = 1;
                }
            } else {
                if (lo[k] < 0)
                    lo[k] = 0;
                if (hi[k] > n - 1)
                    hi[k] = n - 1;
            }
        }
        /* a wrapped cell coordinate: the division only off [0, n) (two of
         * them per cell are most of a 2D query's time; docs/perf/space.md) */
#define WRAPPED(c_, k_)                                                                            \
    (wrap[k_] && ((c_) < 0 || (c_) >= lv->ncell[k_])                                               \
         ? (((c_) % lv->ncell[k_]) + lv->ncell[k_]) % lv->ncell[k_]                                \
         : (c_))
        for (int64_t cz = lo[2]; cz <= hi[2]; cz++) {
            int64_t iz = WRAPPED(cz, 2);
            for (int64_t cy = lo[1]; cy <= hi[1]; cy++) {
                int64_t iy = WRAPPED(cy, 1);
                uint64_t base =
                    ((uint64_t)iz * (uint64_t)lv->ncell[1] + (uint64_t)iy) * (uint64_t)lv->ncell[0];
                for (int64_t cx = lo[0]; cx <= hi[0]; cx++) {
                    int64_t ix = WRAPPED(cx, 0);
                    uint64_t lin = base + (uint64_t)ix;
                    for (int32_t j = lv->head[bucket_of(lv, lin)]; j >= 0; j = g->next[j]) {
                        if (!lv->dense && g->cell[j] != lin)
                            continue; /* hash collision: another cell's grain */
                        const double *xj = &p->x[3 * (size_t)j];
                        double d[PK_MAXDIM] = {0, 0, 0};
                        double d2 = 0;
                        for (int k = 0; k < dim; k++) {
                            d[k] = xj[k] - x[k];
                            /* |d| <= L/2 is already the minimum image: skip
                             * the division (same result, fewer instructions) */
                            if (g->box.periodic[k] && fabs(d[k]) > 0.5 * g->box.L[k])
                                d[k] -= g->box.L[k] * nearbyint(d[k] / g->box.L[k]);
                            d2 += d[k] * d[k];
                        }
                        double s = r + p->r[j] + g->gap + extra;
                        if (d2 < s * s) {
                            if (!fn)
                                return 1;
                            int stop = fn((size_t)j, d, d2, ctx);
                            if (stop)
                                return stop;
                        }
                    }
                }
            }
        }
    }
    return 0;
#undef WRAPPED
}

int pk_grid_query(const pk_grid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                  double extra, pk_grid_visit fn, void *ctx)
{
    if (!fn)
        return 0;
    return scan(g, p, x, r, extra, fn, ctx);
}

int pk_grid_overlaps(const pk_grid *g, const pk_particles *p, const double x[PK_MAXDIM], double r)
{
    return scan(g, p, x, r, 0.0, NULL, NULL);
}
