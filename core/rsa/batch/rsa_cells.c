/* rsa_cells.c — the dense cell store of a batched run and its filter of
 * attempts.  Contract: rsa_cells.h (exactness: README.md). */
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
        C->h[k] = span[k] / (double)C->n[k];
        C->inv_h[k] = span[k] > 0 ? (double)C->n[k] / span[k] : 0;
        C->inv_h2[k] = span[k] > 0 ? (double)(2 * C->n[k]) / span[k] : 0;
        C->jmax[k] = 2 * C->n[k] - 1;
    }
    /* Seams (pk_rsa_cells_seam): off them every neighbour is nearer than
     * 2h <= L/2 on each periodic axis, where the hash's fixed offsets hold (no
     * image needed).  The key's cell is 0 iff 2·(x - lo)·inv_h < 2 (round-off
     * ~1e-16 relative); the margin 1e-9·h keeps the bounds on the safe side. */
    for (int k = 0; k < PK_MAXDIM; k++) {
        C->seam_lo[k] = -INFINITY;
        C->seam_hi[k] = INFINITY;
        if (k >= b->dim || !b->periodic[k])
            continue;
        if (C->n[k] < 4) {
            C->seam_lo[k] = INFINITY; /* always */
            continue;
        }
        C->seam_lo[k] = C->lo[k] + C->h[k] * (1 + 1e-9);
        C->seam_hi[k] = C->lo[k] + (double)(C->n[k] - 1) * C->h[k] * (1 - 1e-9);
    }
    C->ncell = nc;
    C->s2_lo = C->s2 * (1 - PK_RSA_CELLS_BAND);
    C->s2_hi = C->s2 * (1 + PK_RSA_CELLS_BAND);
    C->q2_lo = C->s2 * (1 - PK_RSA_CELLS_QBAND);
    C->q2_hi = C->s2 * (1 + PK_RSA_CELLS_QBAND);
    for (int k = 0; k < PK_MAXDIM; k++)
        C->hq[k] = C->h[k] / PK_RSA_CELLS_QSTEPS;
    uint64_t stride = 1;
    for (int k = 0; k < PK_MAXDIM; k++) {
        C->stride[k] = stride;
        C->base += k < b->dim ? stride : 0; /* +1 per used axis: the ghost layer */
        stride *= (uint64_t)C->np[k];
    }
    set_offsets(C);
    /* four records to a cache line; all empty (0xff bytes: PK_RSA_CELLS_NONE) */
    C->cell = aligned_alloc(64, (nc * sizeof *C->cell + 63) / 64 * 64);
    if (!C->cell)
        return -1;
    memset(C->cell, 0xff, nc * sizeof *C->cell);
    C->occ = calloc(nc / 8 + 16, 1);
    if (!C->occ) {
        pk_rsa_cells_free(C);
        return -1;
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
    C->nrow = zr ? 9 : 3;
    for (int r = 0; r < C->nrow; r++)
        C->row[r] = (int64_t)(r / 3 - zr) * (int64_t)C->stride[2] +
            (int64_t)(r % 3 - 1) * (int64_t)C->stride[1] - 1;
    for (unsigned oct = 0; oct < 8; oct++) {
        int cnt = 0;
        for (int rank = 0; rank < 16; rank++) /* rank 0: the cell itself */
            for (int dz = -zr; dz <= zr; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int d[3] = {dx, dy, dz};
                        if (offset_rank(C->dim, d, oct) == rank) {
                            int r = (dz + zr) * 3 + dy + 1;
                            for (unsigned pat = 0; pat < 8; pat++)
                                if (pat >> (dx + 1) & 1)
                                    C->order[oct][r][pat] |= 1u << cnt;
                            C->shift[oct][cnt][0] = dx * C->h[0];
                            C->shift[oct][cnt][1] = dy * C->h[1];
                            C->shift[oct][cnt][2] = dz * C->h[2];
                            C->off[oct][cnt++] = ((int64_t)dz * C->np[1] + dy) * C->np[0] + dx;
                        }
                    }
        C->noff = cnt;
    }
}

void pk_rsa_cells_free(pk_rsa_cells *C)
{
    free(C->cell);
    free(C->occ);
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
                        (uint64_t)C->np[0] +
                    (uint64_t)a[0][xx];
    return cnt;
}

/* A new pool entry (offsets f, index id) in front of chain `next`; its number,
 * or -1 when out of memory. */
static int64_t pool_push(pk_rsa_cells *C, const float *f, uint32_t id, int32_t next)
{
    if (C->nextra + 1 > C->capextra) {
        size_t cap = C->capextra ? 2 * C->capextra : 1024;
        pk_rsa_extra *e = realloc(C->extra, cap * sizeof *e);
        if (!e)
            return -1;
        C->extra = e;
        C->capextra = cap;
    }
    if (C->nextra >= PK_RSA_CELLS_POOL)
        return -1;
    pk_rsa_extra *e = &C->extra[C->nextra];
    memcpy(e->x, f, sizeof e->x);
    e->id = id;
    e->next = next;
    return (int64_t)C->nextra++;
}

/* Offset f from a cell's corner in 16-bit steps, rounded down (clamped:
 * round-off at the range ends). */
static uint16_t qstep(const pk_rsa_cells *C, int k, float f)
{
    double v = C->hq[k] > 0 ? floor((double)f / C->hq[k]) : 0;
    return (uint16_t)(v < 0 ? 0 : (v > 65535 ? 65535 : v));
}

static int store(pk_rsa_cells *C, uint64_t lin, const float *f, uint32_t id)
{
    pk_rsa_cell1 *c = &C->cell[lin];
    C->occ[lin >> 3] |= (uint8_t)(1u << (lin & 7));
    if (c->id == PK_RSA_CELLS_NONE) {
        memcpy(c->x, f, 3 * sizeof *f);
        c->id = id;
        return 0;
    }
    int32_t head;
    uint32_t three = 0;
    if (c->id & PK_RSA_CELLS_MORE) {
        head = (int32_t)(c->id & PK_RSA_CELLS_POOL);
        three = PK_RSA_CELLS_THREE;
    } else { /* a second grain: the inline one moves to the pool, the chain starts there */
        int64_t e = pool_push(C, c->x, c->id, -1);
        if (e < 0)
            return -1;
        head = (int32_t)e;
        uint16_t q[2][3];
        for (int k = 0; k < 3; k++) {
            q[0][k] = qstep(C, k, c->x[k]);
            q[1][k] = qstep(C, k, f[k]);
        }
        memcpy(c->q, q, sizeof q); /* (the union's other member: x is read no more) */
    }
    int64_t e = pool_push(C, f, id, head);
    if (e < 0)
        return -1;
    c->id = PK_RSA_CELLS_MORE | three | (uint32_t)e;
    return 0;
}

int pk_rsa_cells_insert(pk_rsa_cells *C, const double *x, uint32_t id)
{
    if (id & PK_RSA_CELLS_MORE)
        return -1; /* indices below 2^31 only */
    /* padded coordinates: the real one, plus the ghost on the far side of a
     * periodic axis when the cell touches the seam; the offset from the real
     * cell's corner serves the ghost too (rsa_cells.h) */
    int64_t a[3][2] = {{0}};
    int m[3] = {1, 1, 1};
    float f[3] = {0, 0, 0};
    for (int k = 0; k < C->dim; k++) {
        int64_t i = pk_rsa_cells_coord(C, k, x[k]);
        f[k] = (float)(x[k] - (C->lo[k] + (double)i * C->h[k]));
        a[k][0] = i + 1;
        if (C->periodic[k] && i == 0)
            a[k][m[k]++] = C->n[k] + 1;
        else if (C->periodic[k] && i == C->n[k] - 1)
            a[k][m[k]++] = 0;
    }
    if (m[0] * m[1] * m[2] == 1) /* off the seams: no ghost */
        return store(C,
                     ((uint64_t)a[2][0] * (uint64_t)C->np[1] + (uint64_t)a[1][0]) *
                             (uint64_t)C->np[0] +
                         (uint64_t)a[0][0],
                     f, id);
    for (int z = 0; z < m[2]; z++)
        for (int y = 0; y < m[1]; y++)
            for (int xx = 0; xx < m[0]; xx++) {
                uint64_t lin = ((uint64_t)a[2][z] * (uint64_t)C->np[1] + (uint64_t)a[1][y]) *
                        (uint64_t)C->np[0] +
                    (uint64_t)a[0][xx];
                if (store(C, lin, f, id) != 0)
                    return -1;
            }
    return 0;
}

/* One stored grain (offsets f, index id) against x, whose offsets from the
 * grain's cell corner are q: the float answer outside the band, the exact
 * predicate inside (rsa_cells.h). */
static inline int near_one(const pk_rsa_cells *C, const float *f, uint32_t id, const double *q,
                           const double *px, const double *x)
{
    double d0 = q[0] - f[0], d1 = q[1] - f[1], d2 = q[2] - f[2];
    double s = d0 * d0 + d1 * d1 + d2 * d2;
    if (s < C->s2_lo)
        return 1;
    if (s >= C->s2_hi)
        return 0;
    return pk_rsa_cells_close(C, &px[3 * (size_t)id], x);
}

/* Squared distance from the offsets q (less half a step) to a grain's 16-bit ones. */
static inline double qdist2(const pk_rsa_cells *C, const double *qh, const uint16_t *u)
{
    double d0 = qh[0] - (double)u[0] * C->hq[0], d1 = qh[1] - (double)u[1] * C->hq[1],
           d2 = qh[2] - (double)u[2] * C->hq[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

/* The grains of a nonempty cell c (corner: x's cell corner + sh) against x
 * (offsets q0 from its own cell's corner).  A two-grain cell is decided by
 * its 16-bit offsets when both lie outside their band: the pool (a miss per
 * entry) only serves cells of three grains and pairs in the band. */
static inline int cell_hits(const pk_rsa_cells *C, const pk_rsa_cell1 *c, const double *q0,
                            const double *sh, const double *px, const double *x)
{
    const double q[3] = {q0[0] - sh[0], q0[1] - sh[1], q0[2] - sh[2]};
    const uint32_t b = c->id;
    if (!(b & PK_RSA_CELLS_MORE))
        return near_one(C, c->x, b, q, px, x);
    if (!(b & PK_RSA_CELLS_THREE)) {
        /* a step's centre is u + 1/2: compare with q - hq/2 */
        const double qh[3] = {q[0] - 0.5 * C->hq[0], q[1] - 0.5 * C->hq[1], q[2] - 0.5 * C->hq[2]};
        const double a = qdist2(C, qh, c->q[0]), d = qdist2(C, qh, c->q[1]);
        if (a < C->q2_lo || d < C->q2_lo)
            return 1;
        if (a >= C->q2_hi && d >= C->q2_hi)
            return 0;
    }
    for (int32_t e = (int32_t)(b & PK_RSA_CELLS_POOL); e >= 0; e = C->extra[e].next)
        if (near_one(C, C->extra[e].x, C->extra[e].id, q, px, x))
            return 1;
    return 0;
}

/* Stores larger than this outgrow the per-core caches: the filter fetches the
 * 3^dim records around the attempt PREFETCH_AHEAD places on while it tests
 * this one (sorted attempts still jump between planes of cells). */
#define PREFETCH_BYTES ((uint64_t)4 << 20)
#define PREFETCH_AHEAD 8

size_t pk_rsa_cells_filter(const pk_rsa_cells *C, const double *px, const double *qs,
                           const double *pos, const uint32_t *idx, const uint32_t *key, size_t n,
                           uint32_t *kept)
{
    size_t cnt = 0;
    const int nrow = C->nrow;
    const uint8_t *occ = C->occ;
    const size_t ahead = C->ncell * sizeof *C->cell > PREFETCH_BYTES ? PREFETCH_AHEAD : n;
    for (size_t i = 0; i < n; i++) {
        if (i + ahead < n) { /* the one or two cache lines of each row of records */
            const pk_rsa_cell1 *p = &C->cell[pk_rsa_cells_index(key[i + ahead])];
            const int64_t *row = C->row;
#define PK_FETCH_ROW(r) (__builtin_prefetch(p + row[r]), __builtin_prefetch(p + row[r] + 2))
            PK_FETCH_ROW(0), PK_FETCH_ROW(1), PK_FETCH_ROW(2);
            if (nrow == 9) {
                PK_FETCH_ROW(3), PK_FETCH_ROW(4), PK_FETCH_ROW(5);
                PK_FETCH_ROW(6), PK_FETCH_ROW(7), PK_FETCH_ROW(8);
            }
#undef PK_FETCH_ROW
        }
        const double *x = &pos[3 * (idx ? (size_t)idx[i] : i)];
        const uint64_t lin = pk_rsa_cells_index(key[i]);
        const unsigned oct = pk_rsa_cells_octant(key[i]);
        const pk_rsa_cell1 *c0 = &C->cell[lin];
        const double *q = &qs[3 * i]; /* offsets of x from its cell's corner (the key's) */
        /* the cell itself first (offset 0, the likeliest overlap), then the
         * nonempty cells around, as bits of the near-first order off[oct] */
        const int64_t *off = C->off[oct];
        const double(*sh)[3] = C->shift[oct];
        uint32_t m = occ[lin >> 3] >> (lin & 7) & 1;
        int hit = 0, around = 0;
        for (;;) {
            if (!m) {
                if (around)
                    break;
                const uint32_t(*ord)[8] = C->order[oct];
                const int64_t *row = C->row;
#define PK_ROW(r) ord[r][pk_rsa_cells_bits3(occ, lin + (uint64_t)row[r])]
                m = PK_ROW(0) | PK_ROW(1) | PK_ROW(2);
                if (nrow == 9)
                    m |= PK_ROW(3) | PK_ROW(4) | PK_ROW(5) | PK_ROW(6) | PK_ROW(7) | PK_ROW(8);
#undef PK_ROW
                m &= ~(uint32_t)1;
                around = 1;
                continue;
            }
            int t = __builtin_ctz(m);
            m &= m - 1;
            if ((hit = cell_hits(C, c0 + off[t], q, sh[t], px, x)))
                break;
        }
        kept[cnt] = (uint32_t)i;
        cnt += !hit; /* branch-free: most points are rejected */
    }
    return cnt;
}
