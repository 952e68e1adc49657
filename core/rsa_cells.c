#include "rsa_cells.h"

#include <stdlib.h>
#include <string.h>

#define MAX_CELLS ((uint64_t)1 << 28) /* the index field of a key (rsa_cells.h) */

/* Cells per axis with edge h >= c·(1 + 1e-9): the margin keeps round-off of
 * the cell coordinate from putting two centres closer than c two cells apart. */
static int64_t axis_cells(double span, double c)
{
    double m = floor(span / (c * (1 + 1e-9)));
    return m < 1 ? 1 : (m > 1e9 ? (int64_t)1e9 : (int64_t)m);
}

uint64_t pk_rsa_cells_count(const pk_box *b, double r, double gap, const double *span)
{
    double c = 2 * r + gap;
    if (!b || b->dim < 2 || b->dim > 3 || !(c > 0))
        return 0;
    uint64_t total = 1;
    for (int k = 0; k < b->dim; k++) {
        if (!(span[k] >= 0))
            return 0;
        int64_t m = axis_cells(span[k], c);
        if (b->periodic[k] && m < 3)
            return 0; /* ±1 neighbours must be distinct cells */
        if (total > MAX_CELLS / (uint64_t)(m + 2))
            return 0;
        total *= (uint64_t)(m + 2);
    }
    return total;
}

static void set_offsets(pk_rsa_cells *C);

int pk_rsa_cells_init(pk_rsa_cells *C, const pk_box *b, double r, double gap, const double *lo,
                      const double *span)
{
    memset(C, 0, sizeof *C);
    uint64_t nc = pk_rsa_cells_count(b, r, gap, span);
    if (nc == 0)
        return -1;
    double s = r + r + gap; /* as pk_grid: (r_i + r_j) + gap */
    C->dim = b->dim;
    C->s2 = s * s;
    for (int k = 0; k < PK_MAXDIM; k++) {
        C->n[k] = C->np[k] = 1;
        C->quarter[k] = INFINITY;
        if (k >= b->dim)
            continue;
        C->periodic[k] = b->periodic[k];
        C->L[k] = b->L[k];
        if (b->periodic[k])
            C->quarter[k] = 0.25 * b->L[k];
        C->lo[k] = lo[k];
        C->n[k] = axis_cells(span[k], 2 * r + gap);
        C->np[k] = C->n[k] + 2;
        C->inv_h[k] = span[k] > 0 ? (double)C->n[k] / span[k] : 0;
        C->inv_h2[k] = span[k] > 0 ? (double)(2 * C->n[k]) / span[k] : 0;
        C->jmax[k] = 2 * C->n[k] - 1;
    }
    C->ncell = nc;
    uint64_t stride = 1;
    for (int k = 0; k < PK_MAXDIM; k++) {
        C->stride[k] = stride;
        C->base += k < b->dim ? stride : 0; /* +1 per used axis: the ghost layer */
        stride *= (uint64_t)C->np[k];
    }
    set_offsets(C);
    /* one record = one cache line */
    C->cell = aligned_alloc(64, nc * sizeof *C->cell);
    if (!C->cell)
        return -1;
    for (uint64_t i = 0; i < nc; i++) {
        C->cell[i].n = 0;
        C->cell[i].more = -1;
    }
    /* seam flags (rsa_cells.h) of the padded cells; ghosts are never a query's own cell */
    uint64_t i = 0;
    for (int64_t z = 0; z < C->np[2]; z++)
        for (int64_t y = 0; y < C->np[1]; y++)
            for (int64_t x = 0; x < C->np[0]; x++, i++) {
                int64_t c[3] = {x - 1, y - 1, z - 1}; /* real coordinates */
                int seam = 0;
                for (int k = 0; k < C->dim; k++)
                    seam |= C->periodic[k] && (C->n[k] < 4 || c[k] <= 0 || c[k] >= C->n[k] - 1);
                C->cell[i].seam = seam;
            }
    return 0;
}

/* Rank of neighbour offset d (components -1..0..1) for a point in octant oct:
 * sides the point is near first, then by number of nonzero components (faces
 * before edges before corners). */
static int offset_rank(int dim, const int d[3], unsigned oct)
{
    int far = 0, nz = 0;
    for (int k = 0; k < dim; k++) {
        int up = oct >> k & 1;
        nz += d[k] != 0;
        far += d[k] == (up ? -1 : 1);
    }
    return far * 4 + nz;
}

static void set_offsets(pk_rsa_cells *C)
{
    int zr = C->dim == 3 ? 1 : 0;
    for (unsigned oct = 0; oct < 8; oct++) {
        int cnt = 0;
        for (int rank = 1; rank < 16; rank++)
            for (int dz = -zr; dz <= zr; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int d[3] = {dx, dy, dz};
                        if ((dx || dy || dz) && offset_rank(C->dim, d, oct) == rank)
                            C->off[oct][cnt++] = ((int64_t)dz * C->np[1] + dy) * C->np[0] + dx;
                    }
        C->noff = cnt;
    }
}

void pk_rsa_cells_free(pk_rsa_cells *C)
{
    free(C->cell);
    free(C->extra);
    memset(C, 0, sizeof *C);
}

int pk_rsa_cells_around(const pk_rsa_cells *C, const double *x, uint64_t out[27])
{
    int64_t a[3][3] = {{0}};
    int m[3] = {1, 1, 1};
    for (int k = 0; k < C->dim; k++) {
        int64_t i = pk_rsa_cells_coord(C, k, x[k]);
        m[k] = 0;
        for (int64_t d = -1; d <= 1; d++) {
            int64_t j = i + d;
            if (j < 0 || j >= C->n[k]) {
                if (!C->periodic[k])
                    continue;
                j = j < 0 ? j + C->n[k] : j - C->n[k];
            }
            a[k][m[k]++] = j + 1;
        }
    }
    int cnt = 0;
    for (int z = 0; z < m[2]; z++)
        for (int y = 0; y < m[1]; y++)
            for (int xx = 0; xx < m[0]; xx++)
                out[cnt++] = ((uint64_t)a[2][z] * (uint64_t)C->np[1] + (uint64_t)a[1][y]) *
                                 (uint64_t)C->np[0] + (uint64_t)a[0][xx];
    return cnt;
}

static int store(pk_rsa_cells *C, uint64_t lin, const double *p)
{
    pk_rsa_cell2 *c = &C->cell[lin];
    if (c->n < 2) {
        memcpy(c->x[c->n], p, 3 * sizeof *p);
    } else {
        if (C->nextra == C->capextra) {
            size_t cap = C->capextra ? 2 * C->capextra : 1024;
            pk_rsa_extra *e = realloc(C->extra, cap * sizeof *e);
            if (!e)
                return -1;
            C->extra = e;
            C->capextra = cap;
        }
        pk_rsa_extra *e = &C->extra[C->nextra];
        memcpy(e->x, p, 3 * sizeof *p);
        e->next = c->more;
        c->more = (int32_t)C->nextra++;
    }
    c->n++;
    return 0;
}

int pk_rsa_cells_insert(pk_rsa_cells *C, const double *x)
{
    double p[3] = {x[0], x[1], C->dim == 3 ? x[2] : 0};
    /* padded coordinates: the real one, plus the ghost on the far side of a
     * periodic axis when the cell touches the seam */
    int64_t a[3][2] = {{0}};
    int m[3] = {1, 1, 1};
    for (int k = 0; k < C->dim; k++) {
        int64_t i = pk_rsa_cells_coord(C, k, x[k]);
        a[k][0] = i + 1;
        if (C->periodic[k] && i == 0)
            a[k][m[k]++] = C->n[k] + 1;
        else if (C->periodic[k] && i == C->n[k] - 1)
            a[k][m[k]++] = 0;
    }
    for (int z = 0; z < m[2]; z++)
        for (int y = 0; y < m[1]; y++)
            for (int xx = 0; xx < m[0]; xx++) {
                uint64_t lin = ((uint64_t)a[2][z] * (uint64_t)C->np[1] + (uint64_t)a[1][y]) *
                                   (uint64_t)C->np[0] + (uint64_t)a[0][xx];
                if (store(C, lin, p) != 0)
                    return -1;
            }
    return 0;
}

static inline int cell_hits(const pk_rsa_cells *C, const pk_rsa_cell2 *c, const double *x)
{
    int n = c->n;
    if (n == 0)
        return 0;
    if (pk_rsa_cells_close(C, c->x[0], x))
        return 1;
    if (n == 1)
        return 0;
    if (pk_rsa_cells_close(C, c->x[1], x))
        return 1;
    for (int32_t e = c->more; e >= 0; e = C->extra[e].next)
        if (pk_rsa_cells_close(C, C->extra[e].x, x))
            return 1;
    return 0;
}

/* Away from seams: d as is (pk_rsa_cells_key), the z term +0 in 2D. */
static inline int near_direct(const double *a, const double *x, double s2)
{
    double d0 = a[0] - x[0], d1 = a[1] - x[1], d2 = a[2] - x[2];
    return d0 * d0 + d1 * d1 + d2 * d2 < s2;
}

static inline int cell_hits_direct(const pk_rsa_cells *C, const pk_rsa_cell2 *c, const double *x)
{
    int n = c->n;
    if (n == 0)
        return 0;
    if (near_direct(c->x[0], x, C->s2))
        return 1;
    if (n == 1)
        return 0;
    if (near_direct(c->x[1], x, C->s2))
        return 1;
    for (int32_t e = c->more; e >= 0; e = C->extra[e].next)
        if (near_direct(C->extra[e].x, x, C->s2))
            return 1;
    return 0;
}

/* Stores larger than this outgrow the per-core caches: the filter fetches the
 * 3^dim records around the attempt PREFETCH_AHEAD places on while it tests
 * this one (sorted attempts still jump between planes of cells). */
#define PREFETCH_BYTES ((uint64_t)4 << 20)
#define PREFETCH_AHEAD 8

size_t pk_rsa_cells_filter(const pk_rsa_cells *C, const double *pos, const uint32_t *key, size_t n,
                           uint32_t *kept)
{
    size_t cnt = 0;
    const int noff = C->noff;
    int64_t row[9]; /* first record of each row of 3 around a cell */
    int nrow = 0;
    for (int64_t dz = -(C->dim == 3); dz <= (C->dim == 3); dz++)
        for (int64_t dy = -1; dy <= 1; dy++)
            row[nrow++] = dz * (int64_t)C->stride[2] + dy * (int64_t)C->stride[1] - 1;
    const size_t ahead = C->ncell * sizeof *C->cell > PREFETCH_BYTES ? PREFETCH_AHEAD : n;
    for (size_t i = 0; i < n; i++) {
        if (i + ahead < n) {
            const pk_rsa_cell2 *p = &C->cell[pk_rsa_cells_index(key[i + ahead])];
            for (int r = 0; r < nrow; r++) {
                __builtin_prefetch(p + row[r]);
                __builtin_prefetch(p + row[r] + 1);
                __builtin_prefetch(p + row[r] + 2);
            }
        }
        const double *x = &pos[3 * i];
        const pk_rsa_cell2 *c0 = &C->cell[pk_rsa_cells_index(key[i])];
        const int64_t *off = C->off[pk_rsa_cells_octant(key[i])];
        int hit;
        if (c0->seam) {
            hit = cell_hits(C, c0, x);
            for (int q = 0; q < noff && !hit; q++)
                hit = cell_hits(C, c0 + off[q], x);
        } else {
            hit = cell_hits_direct(C, c0, x);
            for (int q = 0; q < noff && !hit; q++)
                hit = cell_hits_direct(C, c0 + off[q], x);
        }
        kept[cnt] = (uint32_t)i;
        cnt += !hit; /* branch-free: most points are rejected */
    }
    return cnt;
}
