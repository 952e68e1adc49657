/* gap_audit.c — the exact, independent gap check of a finished packing.
 * Contract: core/space/gap_audit.h. */
#include "gap_audit.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* The audit's own neighbour search (shared with no placer, so a placer's bug
 * cannot hide in it): grains go to levels by radius, level L holding
 * r in (r_max/2^(L+1), r_max/2^L] (the finest level also everything smaller),
 * each level a uniform cell grid of edge e_L >= 2·r_max/2^L + h.  A pair with
 * gap < h is then within one cell of the finer grain's cell in the coarser
 * grain's level grid (d < r_i + r_j + h <= e_L), so each grain scans the 3^dim
 * cells around it in its own level and in every coarser one: O(N) work per
 * level, whatever the size ratio (10^6 disks of a 2D Fuller curve 1:1000:
 * 0.53 s; a sort-and-sweep along x is quadratic there, docs/perf/space.md).
 *
 * The horizon grows: pairs_below needs h >= required; the smallest gap of a
 * packing is usually far below r_max (the caller's horizon), so the first
 * pass looks at h = max(required, r_min/4) and only a pass that meets no pair
 * at all is repeated with 4h, up to the caller's horizon.  The smallest gap
 * over pairs closer than h is then the smallest over pairs closer than the
 * horizon. */

#define MAX_LEVELS 40

typedef struct level_grid {
    double edge[PK_MAXDIM]; /* cell edge per axis (L_k / n_k) */
    int64_t n[PK_MAXDIM];   /* cells per axis (1 on unused axes) */
    size_t *start;          /* [ncell + 1] CSR: grains of cell c are ids[start[c] .. start[c+1]) */
    size_t *ids;
    double *q;    /* [count][4] centre and radius of ids[s], in the same (cell)
                                 order: a cell's candidates are contiguous in memory */
    size_t count; /* grains in the level */
} level_grid;

typedef struct audit {
    const pk_box *b;
    const pk_particles *p;
    int nlevel;
    double r_up[MAX_LEVELS]; /* radius bound of level L: r_max / 2^L */
    int *level;              /* [n] level of each grain */
    level_grid g[MAX_LEVELS];
} audit;

static void grids_free(audit *A)
{
    for (int l = 0; l < A->nlevel; l++) {
        free(A->g[l].start);
        free(A->g[l].ids);
        free(A->g[l].q);
        A->g[l].start = NULL;
        A->g[l].ids = NULL;
        A->g[l].q = NULL;
    }
}

/* Cell coordinate of x along axis k in grid G: wrapped into [0, L) on a
 * periodic axis, clamped on a walled one (grains lie in [0, L]; round-off
 * may put one a hair outside). */
static int64_t cell_of(const level_grid *G, const pk_box *b, int k, double x)
{
    if (b->periodic[k])
        x -= b->L[k] * floor(x / b->L[k]);
    double f = x / G->edge[k];
    int64_t c = f < 0 ? 0 : (int64_t)f;
    return c >= G->n[k] ? G->n[k] - 1 : c;
}

static uint64_t cell_index(const level_grid *G, const int64_t *c)
{
    return ((uint64_t)c[2] * (uint64_t)G->n[1] + (uint64_t)c[1]) * (uint64_t)G->n[0] +
        (uint64_t)c[0];
}

/* The grains in (level, cell) order: keys base_l + cell (32 bits: at most
 * 4 cells per grain and level), an LSD radix sort of 11 bits a pass, then each
 * level's CSR and its centres and radii gathered in that order (a counting
 * sort straight into the cells writes to random places of 40 MB at 10^6
 * grains). */
static int fill_by_cell(audit *A)
{
    const pk_box *b = A->b;
    const pk_particles *p = A->p;
    const size_t n = p->n;
    uint64_t base[MAX_LEVELS], total = 0;
    for (int l = 0; l < A->nlevel; l++) {
        base[l] = total;
        if (A->g[l].count)
            total += (uint64_t)A->g[l].n[0] * (uint64_t)A->g[l].n[1] * (uint64_t)A->g[l].n[2];
    }
    if (total > UINT32_MAX || n > UINT32_MAX)
        return -1;
    uint32_t *key = malloc(2 * n * sizeof *key), *idx = malloc(2 * n * sizeof *idx);
    if (!key || !idx) {
        free(key);
        free(idx);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        const level_grid *G = &A->g[A->level[i]];
        int64_t c[3] = {0, 0, 0};
        for (int k = 0; k < b->dim; k++)
            c[k] = cell_of(G, b, k, p->x[3 * i + k]);
        key[i] = (uint32_t)(base[A->level[i]] + cell_index(G, c));
        idx[i] = (uint32_t)i;
    }
    uint32_t *k0 = key, *i0 = idx, *k1 = key + n, *i1 = idx + n;
    for (int shift = 0; shift < 32 && (total - 1) >> shift; shift += 11) {
        size_t count[2049] = {0};
        for (size_t i = 0; i < n; i++)
            count[(k0[i] >> shift & 2047) + 1]++;
        for (int d = 0; d < 2048; d++)
            count[d + 1] += count[d];
        for (size_t i = 0; i < n; i++) {
            const size_t t = count[k0[i] >> shift & 2047]++;
            k1[t] = k0[i];
            i1[t] = i0[i];
        }
        uint32_t *tk = k0, *ti = i0;
        k0 = k1, i0 = i1, k1 = tk, i1 = ti;
    }
    size_t s = 0; /* levels come in order: level l's grains are the next count_l */
    for (int l = 0; l < A->nlevel; l++) {
        level_grid *G = &A->g[l];
        for (size_t t = 0; t < G->count; t++, s++) {
            const size_t i = i0[s];
            if (s + 8 < n)
                __builtin_prefetch(&p->x[3 * (size_t)i0[s + 8]]);
            G->start[k0[s] - base[l] + 1]++;
            G->ids[t] = i;
            for (int k = 0; k < 3; k++)
                G->q[4 * t + k] = p->x[3 * i + k];
            G->q[4 * t + 3] = p->r[i];
        }
        if (!G->count)
            continue;
        const uint64_t ncell = (uint64_t)G->n[0] * (uint64_t)G->n[1] * (uint64_t)G->n[2];
        for (uint64_t c = 0; c < ncell; c++)
            G->start[c + 1] += G->start[c];
    }
    free(key);
    free(idx);
    return 0;
}

/* Level grids for pass horizon h: edge >= 2·r_up + h per axis, at most about
 * 4 cells per grain of the level (a few fine grains in a large box). */
static int grids_build(audit *A, double h)
{
    const pk_box *b = A->b;
    for (int l = 0; l < A->nlevel; l++) {
        level_grid *G = &A->g[l];
        if (G->count == 0)
            continue;
        double want = 2 * A->r_up[l] + h;
        for (;;) {
            uint64_t cells = 1;
            for (int k = 0; k < PK_MAXDIM; k++) {
                G->n[k] = 1;
                G->edge[k] = k < b->dim ? b->L[k] : 1;
                if (k >= b->dim)
                    continue;
                double m = floor(b->L[k] / want);
                G->n[k] = m < 1 ? 1 : (m > 1e6 ? 1000000 : (int64_t)m);
                G->edge[k] = b->L[k] / (double)G->n[k];
                cells *= (uint64_t)G->n[k];
            }
            if (cells <= 4 * (uint64_t)G->count + 64)
                break;
            want *= 1.26; /* ~2^(1/3): cells per grain halve every 3 steps in 3D */
        }
        uint64_t ncell = (uint64_t)G->n[0] * (uint64_t)G->n[1] * (uint64_t)G->n[2];
        G->start = calloc(ncell + 1, sizeof *G->start);
        G->ids = malloc(G->count * sizeof *G->ids);
        G->q = malloc(G->count * 4 * sizeof *G->q);
        if (!G->start || !G->ids || !G->q)
            return -1;
    }
    return fill_by_cell(A);
}

/* The distinct cells next to cell c along axis k (itself included): wrapped
 * on periodic axes, clipped on walled ones.  Returns their number. */
static int axis_neighbours(const level_grid *G, const pk_box *b, int k, int64_t c, int64_t out[3])
{
    if (k >= b->dim) {
        out[0] = 0;
        return 1;
    }
    int m = 0;
    for (int64_t d = -1; d <= 1; d++) {
        int64_t j = c + d;
        if (j < 0 || j >= G->n[k]) {
            if (!b->periodic[k])
                continue;
            j = j < 0 ? j + G->n[k] : j - G->n[k];
        }
        int seen = 0;
        for (int q = 0; q < m; q++)
            seen |= out[q] == j;
        if (!seen)
            out[m++] = j;
    }
    return m;
}

/* Squared distance of centres a (grain i) and c (grain j), minimum image on
 * periodic axes: d -= L·nearbyint(d/L), skipped where |d| <= L/2 (nearbyint
 * gives 0 there, so the same bits without a division per axis and pair). */
static double pair_d2(const pk_box *b, const double *a, const double *c)
{
    double d2 = 0;
    for (int k = 0; k < b->dim; k++) {
        double d = c[k] - a[k];
        if (b->periodic[k] && fabs(d) > 0.5 * b->L[k])
            d -= b->L[k] * nearbyint(d / b->L[k]);
        d2 += d * d;
    }
    return d2;
}

/* Grain j (centre and radius xj[0..3]; position sj in its level's order)
 * against the grains of level l in the cells around it.  Within j's own level
 * a pair is taken from the grain later in the level's (cell) order: only the
 * grains before position sj are read, which skips whole cells (the grid's
 * adjacency is symmetric, wrapped cells included, so the other grain of each
 * pair meets it). */
static void scan_level(const audit *A, int l, const double *xj, size_t j, size_t sj, int own,
                       double h, double required, double tol, pk_gap_report *rep)
{
    const pk_box *b = A->b;
    const level_grid *G = &A->g[l];
    if (G->count == 0)
        return;
    int64_t nb[3][3];
    int m[3];
    for (int k = 0; k < PK_MAXDIM; k++)
        m[k] = axis_neighbours(G, b, k, k < b->dim ? cell_of(G, b, k, xj[k]) : 0, nb[k]);
    for (int z = 0; z < m[2]; z++)
        for (int y = 0; y < m[1]; y++)
            for (int x = 0; x < m[0]; x++) {
                const int64_t c[3] = {nb[0][x], nb[1][y], nb[2][z]};
                const uint64_t ci = cell_index(G, c);
                size_t end = G->start[ci + 1];
                if (own && end > sj)
                    end = sj;
                for (size_t s = G->start[ci]; s < end; s++) {
                    const double *xi = &G->q[4 * s];
                    const double d2 = pair_d2(b, xi, xj), reach = xi[3] + xj[3] + h;
                    if (d2 > reach * reach * (1 + 1e-9))
                        continue; /* surely gap >= h (no square root for the many far pairs) */
                    const double gap = sqrt(d2) - (xi[3] + xj[3]); /* (symmetric in i, j) */
                    if (gap >= h)
                        continue;
                    rep->pairs_checked++;
                    if (gap < rep->min_gap) {
                        const size_t i = G->ids[s];
                        rep->min_gap = gap;
                        rep->min_pair[0] = i < j ? i : j;
                        rep->min_pair[1] = i < j ? j : i;
                    }
                    if (gap < required - tol)
                        rep->pairs_below++;
                }
            }
}

/* One pass at horizon h: every pair with gap < h once (from the grain of the
 * finer level, or the later one in a level's order).  Grains are taken in
 * their level grid's cell order, so the cells around consecutive grains are
 * mostly in cache (in index order, 534 000 spheres took 0.59 s). */
static void pass(const audit *A, double h, double required, double tol, pk_gap_report *rep)
{
    for (int lj = 0; lj < A->nlevel; lj++) {
        for (size_t sj = 0; sj < A->g[lj].count; sj++) {
            const size_t j = A->g[lj].ids[sj];
            const double *xj = &A->g[lj].q[4 * sj];
            for (int l = 0; l <= lj; l++)
                scan_level(A, l, xj, j, sj, l == lj, h, required, tol, rep);
        }
    }
}

int pk_gap_audit(const pk_box *b, const pk_particles *p, double required, double tol,
                 double horizon, pk_gap_report *rep)
{
    *rep = (pk_gap_report){
        .min_gap = horizon, .min_pair = {SIZE_MAX, SIZE_MAX}, .min_wall_gap = INFINITY};
    const int dim = b->dim;
    double rmax = 0, rmin = INFINITY;
    for (size_t i = 0; i < p->n; i++) {
        rmax = fmax(rmax, p->r[i]);
        if (p->r[i] > 0)
            rmin = fmin(rmin, p->r[i]);
    }

    /* Wall clearances. */
    for (size_t i = 0; i < p->n; i++)
        for (int k = 0; k < dim; k++) {
            if (b->periodic[k])
                continue;
            double c = fmin(p->x[3 * i + k], b->L[k] - p->x[3 * i + k]) - p->r[i];
            rep->min_wall_gap = fmin(rep->min_wall_gap, c);
            if (c < 0.5 * required - tol)
                rep->walls_below++;
        }
    if (p->n < 2)
        return 0;

    /* Pass horizons: from max(required, r_min/4) up by 4 to the caller's. */
    double h = fmax(required, isfinite(rmin) ? 0.25 * rmin : horizon);
    if (!(h > 0) || h > horizon)
        h = horizon;

    audit A = {.b = b, .p = p};
    A.level = malloc(p->n * sizeof *A.level);
    if (!A.level)
        return -1;
    /* Levels finer than where 2·r_up falls below h/2 would not get smaller
     * cells: they merge into the last (whose r_up still bounds them). */
    A.nlevel = 1;
    A.r_up[0] = rmax;
    while (A.nlevel < MAX_LEVELS && 2 * A.r_up[A.nlevel - 1] >= 0.5 * h &&
           A.r_up[A.nlevel - 1] > 0) {
        A.r_up[A.nlevel] = 0.5 * A.r_up[A.nlevel - 1];
        A.nlevel++;
    }
    for (size_t i = 0; i < p->n; i++) {
        int l = 0;
        while (l + 1 < A.nlevel && p->r[i] <= A.r_up[l + 1])
            l++;
        A.level[i] = l;
        A.g[l].count++;
    }

    int rc = 0;
    for (;;) { /* (each pass counts afresh: h only grows, the last counts are complete) */
        rep->pairs_below = 0;
        rep->pairs_checked = 0;
        if (grids_build(&A, h) != 0) {
            rc = -1;
            break;
        }
        pass(&A, h, required, tol, rep);
        grids_free(&A);
        if (rep->pairs_checked > 0 || h >= horizon)
            break;
        h = fmin(4 * h, horizon);
    }
    grids_free(&A);
    free(A.level);
    return rc;
}
