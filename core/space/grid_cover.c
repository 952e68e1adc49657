/* grid_cover.c — the cover of a pk_ugrid's coarse levels (grid_uniform.h).
 * Contract: core/space/grid_cover.h. */
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
    for (int k = 0; k < g->box.dim; k++) { /* fmin, floor without the libm calls (R >= 0, finite) */
        const double span = ug_fast_floor(2 * R * lv->inv_h[k]) + 2;
        cells *= span < (double)lv->n[k] ? span : (double)lv->n[k];
    }
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
        g->covered[l] =
            cells <= COVER_BALL_CELLS && (double)count[l] * cells <= 8.0 * (double)n + 65536;
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
        /* two balls' tables and their union's (pk_ugrid_cover_move) */
        g->cov_off = malloc(9 * g->cov_nmax * sizeof *g->cov_off);
        g->cov_e2 = malloc(12 * g->cov_nmax * sizeof *g->cov_e2);
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

#define AXIS_WHOLE INT64_MIN

/* The cells of the cover level around the ball (c, R), axis by axis: the
 * cells of the cover level whose box lies within R of c (an image of c on
 * periodic axes), with round-off margins; each cell once (an axis the ball
 * spans whole is taken whole).  Per axis k, cnt[k] cells a (k's slice of
 * the tables, stride cov_nmax): offset off[a] into g->cov and squared slab
 * distance e2[a]; first[k] the first cell unwrapped
 * (AXIS_WHOLE: the axis whole); the ball's cells are those with
 * !(e2₁ + e2₂ > R²) and !(e2₀ + (e2₁ + e2₂) > R²), R² returned (Rm², Rm
 * = R with the margin).  Tabulated first so that a cell costs a sum and a
 * compare, not a modulo and a slab distance. */
static double ball_axes(const pk_ugrid *g, const double c[PK_MAXDIM], double R, int64_t *off_all,
                        double *e2_all, int64_t cnt[PK_MAXDIM], int64_t first[PK_MAXDIM])
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    const double Rm = R * (1 + 1e-9);
    const size_t stride[PK_MAXDIM] = {1, (size_t)lv->n[0], (size_t)lv->n[0] * (size_t)lv->n[1]};
    for (int k = 0; k < PK_MAXDIM; k++) {
        int64_t *off = off_all + k * g->cov_nmax;
        double *e2 = e2_all + k * g->cov_nmax;
        cnt[k] = 1;
        first[k] = 0;
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
        first[k] = whole ? AXIS_WHOLE : (int64_t)lo;
        int32_t wu = ug_wrap_index((int64_t)lo, n); /* then stepped: no modulo per cell */
        for (int64_t a = 0; a < cnt[k]; a++) {
            const int64_t u = (int64_t)lo + a;
            const double s0 = (double)u * h - mg, s1 = (double)(u + 1) * h + mg;
            const double e = whole ? 0 : c[k] < s0 ? s0 - c[k] : c[k] > s1 ? c[k] - s1 : 0;
            off[a] = (int64_t)((size_t)wu * stride[k]);
            e2[a] = e * e;
            wu = wu + 1 == n ? 0 : wu + 1;
        }
    }
    return Rm * Rm;
}

/* Adds j to (add) or drops it from every cover cell the ball (c, R) touches. */
static int cover_ball(pk_ugrid *g, const double c[PK_MAXDIM], double R, int32_t j, int add)
{
    int64_t cnt[PK_MAXDIM], first[PK_MAXDIM];
    const double R2 = ball_axes(g, c, R, g->cov_off, g->cov_e2, cnt, first);
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

/* Both balls' axis tables (ball_axes: e2, cnt, first) over the union of
 * their boxes, in the one unwrapped frame of the two (+inf where a ball's
 * box ends): off, eo, en, cnt_u.  0 when an axis is taken whole or the
 * union spans more than the axis (the centre crossed a periodic seam). */
static int union_axes(const pk_ugrid *g, const double *e2o_all, const int64_t co[PK_MAXDIM],
                      const int64_t fo[PK_MAXDIM], const double *e2n_all,
                      const int64_t cn[PK_MAXDIM], const int64_t fn[PK_MAXDIM], int64_t *off_all,
                      double *eo_all, double *en_all, int64_t cnt_u[PK_MAXDIM])
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    const size_t stride[PK_MAXDIM] = {1, (size_t)lv->n[0], (size_t)lv->n[0] * (size_t)lv->n[1]};
    for (int k = 0; k < PK_MAXDIM; k++) {
        const size_t o = (size_t)k * g->cov_nmax;
        if (fo[k] == AXIS_WHOLE || fn[k] == AXIS_WHOLE)
            return 0;
        const int32_t n = lv->n[k];
        const int64_t lo = fo[k] < fn[k] ? fo[k] : fn[k];
        const int64_t ho = fo[k] + co[k] - 1, hn = fn[k] + cn[k] - 1;
        cnt_u[k] = (ho > hn ? ho : hn) - lo + 1;
        if (cnt_u[k] > n)
            return 0;
        int32_t wu = ug_wrap_index(lo, n);
        for (int64_t a = 0; a < cnt_u[k]; a++) {
            const int64_t ia = lo + a - fo[k], ib = lo + a - fn[k];
            eo_all[o + a] = ia >= 0 && ia < co[k] ? e2o_all[o + ia] : INFINITY;
            en_all[o + a] = ib >= 0 && ib < cn[k] ? e2n_all[o + ib] : INFINITY;
            off_all[o + a] = (int64_t)((size_t)wu * stride[k]);
            wu = wu + 1 == n ? 0 : wu + 1;
        }
    }
    return 1;
}

/* Both balls over one box of cells (union_axes): one walk, each cell's
 * membership in either ball by its own tables. */
static int walk_union(pk_ugrid *g, const int64_t *off, const double *e2o, double R2o,
                      const double *e2n, double R2n, const int64_t cnt[PK_MAXDIM], int32_t j)
{
    const size_t nm = g->cov_nmax;
    const int64_t *o0 = off, *o1 = o0 + nm, *o2 = o1 + nm;
    const double *f0 = e2o, *f1 = f0 + nm, *f2 = f1 + nm;
    const double *h0 = e2n, *h1 = h0 + nm, *h2 = h1 + nm;
    for (int64_t a2 = 0; a2 < cnt[2]; a2++)
        for (int64_t a1 = 0; a1 < cnt[1]; a1++) {
            const double eo = f1[a1] + f2[a2], en = h1[a1] + h2[a2];
            const int row_o = !(eo > R2o), row_n = !(en > R2n);
            if (!row_o && !row_n)
                continue;
            pk_ugrid_cover *row = g->cov + o1[a1] + o2[a2];
            for (int64_t a0 = 0; a0 < cnt[0]; a0++) {
                const int in_o = row_o && !(f0[a0] + eo > R2o);
                const int in_n = row_n && !(h0[a0] + en > R2n);
                if (in_o == in_n)
                    continue;
                if (in_o)
                    cover_drop(row + o0[a0], j);
                else if (cover_push(row + o0[a0], j) != 0)
                    return -1;
            }
        }
    return 0;
}

/* Re-files j from its stored ball to (x, r + cov_r): one walk over the
 * union of the two balls' boxes, and only the cells of one ball and not
 * the other change (a coarse grain's list rebuild moves its ball by a
 * fraction of a cell: ~5 of its ~32 cells change).  Remove + add when an
 * axis is taken whole, across a periodic seam, or to or from cov_big
 * (Fuller-like 1–16 N = 10^4 to jamming: −1.5 % instructions of the run,
 * docs/perf/space.md).  In the cells of both balls j keeps its place, so a
 * query may meet the grains in another order than after a remove + add; an
 * exact tie between two candidates of one EDMD prediction could then
 * resolve otherwise (the earlier in the list wins). */
int pk_ugrid_cover_move(pk_ugrid *g, size_t j, const double x[PK_MAXDIM], double r)
{
    double *b = &g->cov_ball[4 * j];
    const double rn = r + g->cov_r;
    const double c[PK_MAXDIM] = {x[0], g->box.dim > 1 ? x[1] : 0, g->box.dim > 2 ? x[2] : 0};
    const size_t nm3 = 3 * g->cov_nmax;
    int64_t cnt_old[PK_MAXDIM], cnt_new[PK_MAXDIM], cnt_u[PK_MAXDIM];
    int64_t first_old[PK_MAXDIM], first_new[PK_MAXDIM];
    int64_t *off_new = g->cov_off + nm3, *off_u = g->cov_off + 2 * nm3;
    double *e2_new = g->cov_e2 + nm3, *eo_u = g->cov_e2 + 2 * nm3, *en_u = g->cov_e2 + 3 * nm3;
    if (b[3] > 0 && ball_cells(g, rn) <= 2 * COVER_BALL_CELLS) { /* bounded balls both */
        const double R2_old = ball_axes(g, b, b[3], g->cov_off, g->cov_e2, cnt_old, first_old);
        const double R2_new = ball_axes(g, c, rn, off_new, e2_new, cnt_new, first_new);
        if (union_axes(g, g->cov_e2, cnt_old, first_old, e2_new, cnt_new, first_new, off_u, eo_u,
                       en_u, cnt_u)) {
            const int rc = walk_union(g, off_u, eo_u, R2_old, en_u, R2_new, cnt_u, (int32_t)j);
            for (int k = 0; k < PK_MAXDIM; k++)
                b[k] = c[k];
            b[3] = rn;
            return rc;
        }
    }
    pk_ugrid_cover_remove(g, j);
    return pk_ugrid_cover_add(g, j, x, r);
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
static int cover_test(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                      const int32_t *ids, uint32_t n, pk_grid_visit fn, void *ctx)
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
        u[k] = g->box.periodic[k]
            ? ug_wrap_index((int64_t)ug_fast_floor(x[k] * lv->inv_h[k]), lv->n[k])
            : ug_coord(lv, k, x[k]);
    const pk_ugrid_cover *cell =
        &g->cov[((size_t)u[2] * (size_t)lv->n[1] + (size_t)u[1]) * (size_t)lv->n[0] + (size_t)u[0]];
    int stop = cover_test(g, p, x, r, cell->ids, cell->n, fn, ctx);
    if (!stop && g->cov_big.n)
        stop = cover_test(g, p, x, r, g->cov_big.ids, g->cov_big.n, fn, ctx);
    return stop;
}
