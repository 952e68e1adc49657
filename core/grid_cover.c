/* grid_cover.c — the cover of a pk_ugrid's coarse levels (grid_uniform.h). */
#include "grid_cover.h"

#include <math.h>
#include <stdlib.h>

#include "grid_uniform_cells.h"

/* Cover balls: at most this many cells in the box around a ball of a
 * covered level (else the level is scanned as before), and a grain grown
 * past twice that is tested by every cover query instead (cov_big). */
#define COVER_BALL_CELLS 512

/* Cells of the cover level in the box around a ball of radius R. */
static double ball_cells(const pk_ugrid *g, double R)
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    double cells = 1;
    for (int k = 0; k < g->box.dim; k++)
        cells *= fmin((double)lv->n[k], floor(2 * R * lv->inv_h[k]) + 2);
    return cells;
}

int pk_ugrid_cover_init(pk_ugrid *g, const size_t *count, size_t n)
{
    /* the levels coarser than the most populated one, in its cells */
    int busiest = 0;
    for (int l = 1; l < g->nlevel; l++)
        if (count[l] > count[busiest])
            busiest = l;
    g->cov_level = busiest;
    g->cov_r = ldexp(g->r_top, -busiest); /* the busiest level's radii */
    int ncovered = 0;
    for (int l = 0; l < busiest; l++) { /* balls of bounded size, entries O(n) */
        const double cells = ball_cells(g, ldexp(g->r_top, -l) + g->cov_r);
        g->covered[l] = cells <= COVER_BALL_CELLS && (double)count[l] * cells <= 8.0 * (double)n + 65536;
        ncovered += g->covered[l];
    }
    if (ncovered == 0)
        g->cov_r = 0;
    if (ncovered > 0) {
        const pk_ugrid_level *lv = &g->lv[busiest];
        const size_t ncell = (size_t)lv->n[0] * (size_t)lv->n[1] * (size_t)lv->n[2];
        g->cov = calloc(ncell, sizeof *g->cov);
        g->cov_ball = calloc(4 * g->cap, sizeof *g->cov_ball);
        g->cov_nmax = (size_t)(lv->n[0] > lv->n[1] ? lv->n[0] : lv->n[1]);
        if ((size_t)lv->n[2] > g->cov_nmax)
            g->cov_nmax = (size_t)lv->n[2];
        g->cov_off = malloc(3 * g->cov_nmax * sizeof *g->cov_off);
        g->cov_e2 = malloc(3 * g->cov_nmax * sizeof *g->cov_e2);
        if (!g->cov || !g->cov_ball || !g->cov_off || !g->cov_e2)
            return -1;
    }
    return 0;
}

void pk_ugrid_cover_free(pk_ugrid *g)
{
    if (g->cov) {
        const pk_ugrid_level *lv = &g->lv[g->cov_level];
        const size_t ncell = (size_t)lv->n[0] * (size_t)lv->n[1] * (size_t)lv->n[2];
        for (size_t c = 0; c < ncell; c++)
            free(g->cov[c].ids);
    }
    free(g->cov);
    free(g->cov_big.ids);
    free(g->cov_ball);
    free(g->cov_off);
    free(g->cov_e2);
}

static int cover_push(pk_ugrid_cover *cell, int32_t j)
{
    if (cell->n == cell->cap) {
        uint32_t cap = cell->cap ? 2 * cell->cap : 4;
        int32_t *ids = realloc(cell->ids, cap * sizeof *ids);
        if (!ids)
            return -1;
        cell->ids = ids;
        cell->cap = cap;
    }
    cell->ids[cell->n++] = j;
    return 0;
}

static void cover_drop(pk_ugrid_cover *cell, int32_t j)
{
    for (uint32_t q = 0; q < cell->n; q++)
        if (cell->ids[q] == j) {
            cell->ids[q] = cell->ids[--cell->n];
            return;
        }
}

/* Adds j to (add) or drops it from every cover cell the ball (c, R)
 * touches: cells of the cover level whose box lies within R of c (an image
 * of c on periodic axes), with round-off margins; each cell once (an axis
 * the ball spans whole is taken whole).  Per axis the cells' offsets and
 * squared slab distances are tabulated first (g->cov_off, g->cov_e2), so a
 * cell costs a sum and a compare: the first version (modulo and slab
 * distance per cell) made coarse re-inserts 8k instructions each. */
static int cover_ball(pk_ugrid *g, const double c[PK_MAXDIM], double R, int32_t j, int add)
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    const double Rm = R * (1 + 1e-9);
    int64_t cnt[PK_MAXDIM] = {1, 1, 1};
    const size_t stride[PK_MAXDIM] = {1, (size_t)lv->n[0], (size_t)lv->n[0] * (size_t)lv->n[1]};
    for (int k = 0; k < PK_MAXDIM; k++) {
        int64_t *off = g->cov_off + k * g->cov_nmax;
        double *e2 = g->cov_e2 + k * g->cov_nmax;
        if (k >= g->box.dim) {
            off[0] = 0;
            e2[0] = 0;
            continue;
        }
        const int32_t n = lv->n[k];
        const double m = 1e-9 * n, h = g->box.L[k] / n, mg = 1e-9 * h;
        double lo = ug_fast_floor((c[k] - Rm) * lv->inv_h[k] - m);
        double hi = ug_fast_floor((c[k] + Rm) * lv->inv_h[k] + m);
        int whole = 0;
        if (g->box.periodic[k]) {
            if (hi - lo + 1 >= n) {
                lo = 0;
                hi = n - 1;
                whole = 1;
            }
        } else {
            lo = lo > 0 ? lo : 0;
            hi = hi < n - 1 ? hi : n - 1;
        }
        cnt[k] = (int64_t)(hi - lo) + 1;
        for (int64_t a = 0; a < cnt[k]; a++) {
            const int64_t u = (int64_t)lo + a;
            const double s0 = (double)u * h - mg, s1 = (double)(u + 1) * h + mg;
            const double e = whole ? 0 : c[k] < s0 ? s0 - c[k] : c[k] > s1 ? c[k] - s1 : 0;
            off[a] = (int64_t)((size_t)ug_wrap_index(u, n) * stride[k]);
            e2[a] = e * e;
        }
    }
    const double R2 = Rm * Rm;
    const int64_t *o0 = g->cov_off, *o1 = o0 + g->cov_nmax, *o2 = o1 + g->cov_nmax;
    const double *f0 = g->cov_e2, *f1 = f0 + g->cov_nmax, *f2 = f1 + g->cov_nmax;
    for (int64_t a2 = 0; a2 < cnt[2]; a2++)
        for (int64_t a1 = 0; a1 < cnt[1]; a1++) {
            const double e12 = f1[a1] + f2[a2];
            if (e12 > R2)
                continue;
            pk_ugrid_cover *row = g->cov + o1[a1] + o2[a2];
            for (int64_t a0 = 0; a0 < cnt[0]; a0++) {
                if (f0[a0] + e12 > R2)
                    continue;
                if (!add)
                    cover_drop(row + o0[a0], j);
                else if (cover_push(row + o0[a0], j) != 0)
                    return -1;
            }
        }
    return 0;
}

/* j listed with its ball (x, r + cov_r), or taken out of the cells it was
 * listed in (the same cells: the stored ball is walked again). */
int pk_ugrid_cover_add(pk_ugrid *g, size_t j, const double x[PK_MAXDIM], double r)
{
    double *b = &g->cov_ball[4 * j];
    for (int k = 0; k < PK_MAXDIM; k++)
        b[k] = k < g->box.dim ? x[k] : 0;
    b[3] = r + g->cov_r;
    if (ball_cells(g, b[3]) > 2 * COVER_BALL_CELLS) { /* grown far past its level */
        b[3] = -b[3];
        return cover_push(&g->cov_big, (int32_t)j);
    }
    return cover_ball(g, b, b[3], (int32_t)j, 1);
}

void pk_ugrid_cover_remove(pk_ugrid *g, size_t j)
{
    double *b = &g->cov_ball[4 * j];
    if (b[3] > 0)
        cover_ball(g, b, b[3], (int32_t)j, 0);
    else if (b[3] < 0)
        cover_drop(&g->cov_big, (int32_t)j);
    b[3] = 0;
}

/* The grains ids[0..n) within r + r_j of x (minimum image), as scan_cells. */
static int cover_test(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM],
                      double r, const int32_t *ids, uint32_t n, pk_grid_visit fn, void *ctx)
{
    const double M = 6755399441055744.0; /* pk_min_image3 */
    for (uint32_t q = 0; q < n; q++) {
        const int32_t j = ids[q];
        const double *xj = &p->x[3 * (size_t)j];
        double d0 = xj[0] - x[0], d1 = xj[1] - x[1], d2 = xj[2] - x[2];
        d0 -= g->L[0] * ((d0 * g->inv_L[0] + M) - M);
        d1 -= g->L[1] * ((d1 * g->inv_L[1] + M) - M);
        d2 -= g->L[2] * ((d2 * g->inv_L[2] + M) - M);
        const double dd = d0 * d0 + d1 * d1 + d2 * d2;
        const double sr = r + p->r[j];
        if (dd < sr * sr) {
            const double d[PK_MAXDIM] = {d0, d1, d2};
            int stop = fn((size_t)j, d, dd, ctx);
            if (stop)
                return stop;
        }
    }
    return 0;
}

/* The covered levels for a query of radius r <= cov_r: the grains listed
 * in x's cover cell (each once) and the few grown past the cover. */
int pk_ugrid_cover_query(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM],
                         double r, pk_grid_visit fn, void *ctx)
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    int32_t u[PK_MAXDIM] = {0, 0, 0};
    for (int k = 0; k < g->box.dim; k++)
        u[k] = g->box.periodic[k] ? ug_wrap_index((int64_t)ug_fast_floor(x[k] * lv->inv_h[k]), lv->n[k])
                                  : ug_coord(lv, k, x[k]);
    const pk_ugrid_cover *cell =
        &g->cov[((size_t)u[2] * (size_t)lv->n[1] + (size_t)u[1]) * (size_t)lv->n[0] + (size_t)u[0]];
    int stop = cover_test(g, p, x, r, cell->ids, cell->n, fn, ctx);
    if (!stop && g->cov_big.n)
        stop = cover_test(g, p, x, r, g->cov_big.ids, g->cov_big.n, fn, ctx);
    return stop;
}
