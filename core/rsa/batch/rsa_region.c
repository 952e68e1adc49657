/* rsa_region.c — the open region of a batched run: fine-voxel marks from a
 * table, the list of open cells, region draws.  Contract: rsa_region.h. */
#include "rsa_region.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_REACH PK_RSA_REGION_MAX_REACH
#define NOT_MADE 0xff

int pk_rsa_region_init(pk_rsa_region *R, const pk_box *b, const int64_t *n, const double *lo,
                       const double *span, double c, int steps)
{
    memset(R, 0, sizeof *R);
    if (!b || b->dim < 2 || b->dim > 3 || !(c > 0) || steps < 1 || steps > PK_RSA_REGION_MAX_STEPS)
        return -1;
    R->dim = b->dim;
    R->S = b->dim == 3 ? 4 : 8; /* S^dim = 64: one word per cell */
    R->sbits = b->dim == 3 ? 2 : 3;
    uint64_t nc = 1;
    double lmax = 0;
    for (int k = 0; k < PK_MAXDIM; k++) {
        R->n[k] = R->nf[k] = 1;
        R->hf[k] = R->inv_hf[k] = 1;
        if (k >= b->dim)
            continue;
        if (n[k] < 1 || !(span[k] > 0))
            return -1;
        R->periodic[k] = b->periodic[k];
        R->n[k] = n[k];
        R->nf[k] = (int64_t)R->S * n[k];
        R->lo[k] = lo[k];
        R->hf[k] = span[k] / (double)R->nf[k];
        R->inv_hf[k] = (double)R->nf[k] / span[k];
        R->h[k] = span[k] / (double)n[k];
        R->inv_h[k] = (double)n[k] / span[k];
        nc *= (uint64_t)n[k];
        lmax = fmax(lmax, b->L[k]);
    }
    if (nc > UINT32_MAX)
        return -1;
    /* far above the round-off of coordinates and fine-voxel faces, far below
     * any length that matters to the statistics (as rsa_voxels.c) */
    R->margin = 1e-9 * c + 1e-12 * lmax;
    R->ncell = nc;
    R->c = c;
    R->Q = steps;
    double diag2 = 0;
    for (int k = 0; k < b->dim; k++)
        diag2 += R->h[k] * R->h[k];
    R->delta = 0.5 / R->Q * sqrt(diag2);
    double hmin = INFINITY;
    for (int k = 0; k < b->dim; k++)
        hmin = fmin(hmin, R->h[k]);
    R->D = c <= hmin ? 1 : MAX_REACH;
    for (int k = 0; k < b->dim; k++)
        if (b->periodic[k] && n[k] < 2 * R->D + 1)
            return -1; /* the cells around a grain must be distinct */
    size_t ne = b->dim == 3 ? (size_t)R->Q * R->Q * R->Q : (size_t)R->Q * R->Q;
    R->entry = (size_t)(2 * R->D + 1) * (size_t)(2 * R->D + 1) *
        (b->dim == 3 ? (size_t)(2 * R->D + 1) : 1);
    R->tab = malloc(ne * R->entry * sizeof *R->tab);
    R->trows = malloc(ne * sizeof *R->trows);
    R->tcnt = malloc(ne);
    R->tab_far = ne * R->entry * sizeof *R->tab > ((size_t)1 << 20);
    R->covered = calloc(nc, sizeof *R->covered);
    R->list = malloc(nc * sizeof *R->list);
    if (!R->covered || !R->list || !R->tab || !R->trows || !R->tcnt) {
        pk_rsa_region_free(R);
        return -1;
    }
    memset(R->tcnt, NOT_MADE, ne);
    /* Write one word of each page now: a mark's first access to a page is a
     * read (|=), which maps the shared zero page, and its write would then
     * fault a second time.  The pages are the marks', touched by the run anyway. */
    for (uint64_t i = 0; i < nc; i += 4096 / sizeof *R->covered)
        ((volatile uint64_t *)R->covered)[i] = 0;
    const int D = R->D, W = 2 * D + 1, zr = b->dim == 3;
    R->nlist = nc;
    R->nrow = 0; /* the rows of a mark's cells, for pk_rsa_region_prefetch */
    for (int dz = 0; dz < (zr ? W : 1); dz++)
        for (int dy = 0; dy < W; dy++)
            R->roff[R->nrow++] = ((zr ? dz - D : 0) * R->n[1] + dy - D) * R->n[0];
    return 0;
}

void pk_rsa_region_free(pk_rsa_region *R)
{
    free(R->covered);
    free(R->list);
    free(R->tab);
    free(R->trows);
    free(R->tcnt);
    memset(R, 0, sizeof *R);
}

void pk_rsa_region_compact(pk_rsa_region *R)
{
    uint64_t k = 0;
    if (!R->listed) { /* the first: every cell is a candidate, in index order */
        for (uint64_t c = 0; c < R->ncell; c++) {
            R->list[k] = (uint32_t)c;
            k += R->covered[c] != ~(uint64_t)0;
        }
        R->listed = 1;
    } else {
        for (uint64_t i = 0; i < R->nlist; i++) {
            uint32_t c = R->list[i];
            R->list[k] = c;
            k += R->covered[c] != ~(uint64_t)0;
        }
    }
    R->nlist = k;
}

/* Fine voxels j along axis k whose interval [a, a + hf] lies within
 * [x - w, x + w]: j from ceil((x - w - lo)/hf) to floor((x + w - lo)/hf) - 1,
 * unwrapped on periodic axes, clipped on walled ones.  Returns 0 if none. */
static int inside_range(const pk_rsa_region *R, int k, double x, double w, int64_t *j0, int64_t *j1)
{
    *j0 = (int64_t)ceil((x - w - R->lo[k]) * R->inv_hf[k]);
    *j1 = (int64_t)floor((x + w - R->lo[k]) * R->inv_hf[k]) - 1;
    if (!R->periodic[k]) {
        if (*j0 < 0)
            *j0 = 0;
        if (*j1 > R->nf[k] - 1)
            *j1 = R->nf[k] - 1;
    } else if (*j1 - *j0 >= R->nf[k]) {
        *j1 = *j0 + R->nf[k] - 1; /* the whole axis once */
    }
    return *j0 <= *j1;
}

/* Squared distance from x to the far face of fine voxel j along axis k. */
static inline double far2(const pk_rsa_region *R, int k, int64_t j, double x)
{
    double a = R->lo[k] + R->hf[k] * (double)j;
    double d = fmax(x - a, a + R->hf[k] - x);
    return d * d;
}

/* Cell and in-cell index of (unwrapped) fine voxel j along axis k. */
static inline void split(const pk_rsa_region *R, int k, int64_t j, int64_t *cell, int *l)
{
    int64_t q = j >= 0 ? j / R->S : -((-j + R->S - 1) / R->S);
    *l = (int)(j - q * R->S);
    if (q < 0)
        q += R->n[k];
    else if (q >= R->n[k])
        q -= R->n[k];
    *cell = q;
}

/* A fine voxel is marked when its farthest corner is within rad - margin of x:
 * the ball is convex, so the whole voxel is inside.  Rows along x: per fine
 * (z, y) row the covered x voxels are one interval (inside_range with
 * w = sqrt(rem)), split into the ≤ few cells it crosses. */
void pk_rsa_region_cover(pk_rsa_region *R, const double *x, double rad)
{
    const double Rad = rad - R->margin;
    if (!(Rad > 0))
        return;
    const double R2 = Rad * Rad;
    const int S = R->S, dim = R->dim;
    for (int k = 0; k < dim; k++)
        if (R->periodic[k] && !(Rad < R->hf[k] * (double)R->nf[k]))
            return; /* wider than the box: marks are optional, skip (split wraps once) */
    int64_t z0 = 0, z1 = 0, y0, y1;
    if (dim == 3 && !inside_range(R, 2, x[2], Rad, &z0, &z1))
        return;
    if (!inside_range(R, 1, x[1], Rad, &y0, &y1))
        return;
    for (int64_t jz = z0; jz <= z1; jz++) {
        double fz = dim == 3 ? far2(R, 2, jz, x[2]) : 0;
        int64_t cz = 0;
        int lz = 0;
        if (dim == 3)
            split(R, 2, jz, &cz, &lz);
        for (int64_t jy = y0; jy <= y1; jy++) {
            double rem = R2 - fz - far2(R, 1, jy, x[1]);
            if (!(rem > 0))
                continue;
            int64_t x0, x1, cy;
            int ly;
            if (!inside_range(R, 0, x[0], sqrt(rem), &x0, &x1))
                continue;
            split(R, 1, jy, &cy, &ly);
            const unsigned shift = (unsigned)((lz * S + ly) * S);
            uint64_t *row = &R->covered[(uint64_t)(cz * R->n[1] + cy) * (uint64_t)R->n[0]];
            int64_t cx;
            int lx0, lx1;
            split(R, 0, x0, &cx, &lx0);
            int64_t left = x1 - x0 + 1; /* fine voxels still to mark */
            while (left > 0) {
                lx1 = lx0 + (int)(left < S - lx0 ? left : S - lx0) - 1;
                uint64_t bits = ((uint64_t)2 << lx1) - ((uint64_t)1 << lx0);
                row[cx] |= bits << shift;
                left -= lx1 - lx0 + 1;
                lx0 = 0;
                if (++cx == R->n[0])
                    cx = 0;
            }
        }
    }
}

/* Table entry e's words: centre p (offset from its cell's lower corner, per
 * axis), the marks of the cells d = -D..D per axis, word
 * ((dz+D)·W + dy+D)·W + dx+D, W = 2D + 1 (dz = 0 in 2D).  finish_entry then
 * notes its rows; make_mirrored calls both. */
static void make_entry(pk_rsa_region *R, size_t e, const double *p)
{
    const int S = R->S, dim = R->dim, zr = dim == 3, D = R->D, W = 2 * D + 1;
    uint64_t *w = &R->tab[e * R->entry];
    memset(w, 0, R->entry * sizeof *w);
    const double rad = R->c - R->margin - R->delta;
    if (!(rad > 0))
        return;
    const int nj = W * S;                 /* fine voxels j = -D·S .. (D+1)·S - 1 per axis */
    double f[3][(2 * MAX_REACH + 1) * 8]; /* squared distance to the far face of fine voxel j */
    for (int k = 0; k < dim; k++)
        for (int j = 0; j < nj; j++) {
            double a = R->hf[k] * (double)(j - D * S);
            double d = p[k] - a > a + R->hf[k] - p[k] ? p[k] - a : a + R->hf[k] - p[k];
            f[k][j] = d * d;
        }
    const double r2 = rad * rad;
    for (int jz = 0; jz < (zr ? nj : 1); jz++) {
        double fz = zr ? f[2][jz] : 0;
        int dz = jz / S, lz = jz % S; /* dz: cell D + d */
        for (int jy = 0; jy < nj; jy++) {
            double rem = r2 - fz - f[1][jy];
            if (!(rem > 0))
                continue;
            int dy = jy / S, ly = jy % S;
            /* the far faces' distances are V-shaped in jx: the covered ones are
             * an interval around the centre's fine voxel */
            int jc = (int)(p[0] * R->inv_hf[0]) + D * S;
            jc = jc < 0 ? 0 : (jc >= nj ? nj - 1 : jc);
            int j0 = jc, j1 = jc - 1;
            while (j0 > 0 && f[0][j0 - 1] <= rem)
                j0--;
            if (f[0][jc] <= rem)
                for (j1 = jc; j1 + 1 < nj && f[0][j1 + 1] <= rem;)
                    j1++;
            else
                j0 = jc + 1; /* not even the centre's own: none (V-shape) */
            uint64_t *row = &w[((zr ? dz : 0) * W + dy) * W];
            const unsigned shift = (unsigned)((lz * S + ly) * S);
            for (int jx = j0; jx <= j1;) { /* one cell's part of the interval at a time */
                int cx = jx / S, l0 = jx - cx * S, l1 = j1 - cx * S < S - 1 ? j1 - cx * S : S - 1;
                row[cx] |= (((uint64_t)2 << l1) - ((uint64_t)1 << l0)) << shift;
                jx += l1 - l0 + 1;
            }
        }
    }
}

/* The cell of x and its table entry (the centre's step per axis). */
pk_rsa_region_spot pk_rsa_region_locate(const pk_rsa_region *R, const double *x)
{
    const int Q = R->Q;
    pk_rsa_region_spot s = {{0, 0, 0}, 0, 0, 1};
    size_t e = 0;
    for (int k = R->dim - 1; k >= 0; k--) {
        double f = (x[k] - R->lo[k]) * R->inv_h[k];
        int64_t ik = f < 0 ? 0 : (int64_t)f;
        if (ik > R->n[k] - 1)
            ik = R->n[k] - 1;
        double t = f - (double)ik; /* in [0, 1) up to round-off at the range ends */
        int q = t <= 0 ? 0 : (int)(t * Q);
        if (q > Q - 1)
            q = Q - 1;
        s.i[k] = ik;
        s.inner &= ik >= R->D && ik < R->n[k] - R->D;
        e = e * (size_t)Q + (size_t)q;
    }
    s.e = (uint32_t)e;
    s.word = (uint64_t)(s.i[2] * R->n[1] + s.i[1]) * (uint64_t)R->n[0] + (uint64_t)s.i[0];
    return s;
}

/* The centre of entry e's step per axis, as an offset in its cell (z = 0 in 2D). */
static void step_centre(const pk_rsa_region *R, size_t e, double p[3])
{
    p[2] = 0;
    for (int k = 0; k < R->dim; k++) {
        const size_t q = e % (size_t)R->Q;
        e /= (size_t)R->Q;
        p[k] = ((double)q + 0.5) / R->Q * R->h[k];
    }
}

/* Rows of entry e holding a mark (W words along x each); the entry is made. */
static void finish_entry(pk_rsa_region *R, size_t e)
{
    const uint64_t *w = &R->tab[e * R->entry];
    const int W = 2 * R->D + 1;
    uint32_t rows = 0;
    for (int r = 0; r < R->nrow; r++)
        for (int q = 0; q < W; q++)
            rows |= (uint32_t)(w[r * W + q] != 0) << r;
    R->trows[e] = rows;
    R->tcnt[e] = 1;
}

/* A 3D word's fine voxels (bit (lz·4 + ly)·4 + lx) mirrored along x, y, z. */
static inline uint64_t flip_x(uint64_t v)
{
    return (v & 0x1111111111111111ull) << 3 | (v & 0x2222222222222222ull) << 1 |
        (v >> 1 & 0x2222222222222222ull) | (v >> 3 & 0x1111111111111111ull);
}
static inline uint64_t flip_y(uint64_t v)
{
    return (v & 0x000f000f000f000full) << 12 | (v & 0x00f000f000f000f0ull) << 4 |
        (v >> 4 & 0x00f000f000f000f0ull) | (v >> 12 & 0x000f000f000f000full);
}
static inline uint64_t flip_z(uint64_t v)
{
    return v << 48 | (v & 0xffff0000ull) << 16 | (v >> 16 & 0xffff0000ull) | v >> 48;
}

/* Make entry e.  In 3D an entry whose step lies in the upper half of an
 * axis is the mirror image of the one with step Q - 1 - q there (the step
 * centres, the fine voxels and the cells around are symmetric about the
 * cell's middle): made once for the lower octant and mirrored.  A mirrored
 * mark lies within round-off of the direct one's; the margin keeps both
 * inside the ball. */
static void make_mirrored(pk_rsa_region *R, size_t e)
{
    const int Q = R->Q;
    int q[3] = {0, 0, 0}, flip[3] = {0, 0, 0};
    size_t rest = e, lower = 0;
    for (int k = 0; k < R->dim; k++) {
        q[k] = (int)(rest % (size_t)Q);
        rest /= (size_t)Q;
    }
    for (int k = R->dim - 1; k >= 0; k--) {
        flip[k] = R->dim == 3 && 2 * q[k] >= Q;
        lower = lower * (size_t)Q + (size_t)(flip[k] ? Q - 1 - q[k] : q[k]);
    }
    if (R->tcnt[lower] == NOT_MADE) {
        double p[3];
        step_centre(R, lower, p);
        make_entry(R, lower, p);
        finish_entry(R, lower);
    }
    if (lower == e)
        return;
    const int W = 2 * R->D + 1;
    const uint64_t *src = &R->tab[lower * R->entry];
    uint64_t *dst = &R->tab[e * R->entry];
    for (int z = 0; z < W; z++)
        for (int y = 0; y < W; y++)
            for (int x = 0; x < W; x++) {
                uint64_t v = src[((flip[2] ? W - 1 - z : z) * W + (flip[1] ? W - 1 - y : y)) * W +
                                 (flip[0] ? W - 1 - x : x)];
                v = flip[0] ? flip_x(v) : v;
                v = flip[1] ? flip_y(v) : v;
                dst[(z * W + y) * W + x] = flip[2] ? flip_z(v) : v;
            }
    finish_entry(R, e);
}

void pk_rsa_region_prefetch(const pk_rsa_region *R, pk_rsa_region_spot s)
{
    const int D = R->D;
    if (!s.inner)
        return; /* rare: the mark wraps or clips; it only costs the misses */
    const uint64_t *c = &R->covered[s.word];
    for (int q = 0; q < R->nrow; q++) { /* both ends of each row of 2D + 1 words */
        __builtin_prefetch(c + R->roff[q] - D, 1);
        __builtin_prefetch(c + R->roff[q] + D, 1);
    }
    /* The table entry too once the table outgrows a core's cache (16 steps:
     * 4.6 MB, 1 KB an entry; its rows are then the marks' first stall).
     * Entries not made yet are made by the mark itself. */
    if (R->tab_far && R->tcnt[s.e] != NOT_MADE) {
        const char *t = (const char *)&R->tab[s.e * R->entry];
        for (size_t b = 0; b < R->entry * sizeof *R->tab; b += 64)
            __builtin_prefetch(t + b);
    }
}

/* dst[0 .. 2D] |= src[0 .. 2D]: one row of a mark, two words at a time
 * (SSE2, the x86-64 baseline; other targets get the same from the vector
 * extension's lowering). */
typedef uint64_t pk_u64x2 __attribute__((vector_size(16)));

static inline void or_two(uint64_t *dst, const uint64_t *src)
{
    pk_u64x2 a, b;
    memcpy(&a, dst, sizeof a);
    memcpy(&b, src, sizeof b);
    a |= b;
    memcpy(dst, &a, sizeof a);
}

static inline void or_row(uint64_t *dst, const uint64_t *src, int D)
{
    if (D == 2) {
        or_two(dst, src);
        or_two(dst + 2, src + 2);
        dst[4] |= src[4];
    } else {
        or_two(dst, src);
        dst[2] |= src[2];
    }
}

void pk_rsa_region_mark_at(pk_rsa_region *R, pk_rsa_region_spot s)
{
    const int dim = R->dim, D = R->D;
    const size_t e = s.e;
    if (R->tcnt[e] == NOT_MADE)
        make_mirrored(R, e);
    const uint64_t *w = &R->tab[e * R->entry];
    const uint32_t rows = R->trows[e];
    if (s.inner) { /* the common case: no wrap, no wall — fixed offsets */
        uint64_t *base = &R->covered[s.word];
        /* whole rows, two words per operation (rather than the entry's
         * nonzero words one at a time) */
        for (uint32_t m = rows; m; m &= m - 1) {
            const int r = __builtin_ctz(m);
            or_row(base + R->roff[r] - D, w + r * (2 * D + 1), D);
        }
        return;
    }
    /* near a seam or a wall: each word's cell per axis, wrapped or dropped */
    int64_t c[3][2 * MAX_REACH + 1];
    for (int k = 0; k < 3; k++)
        for (int d = -D; d <= D; d++) {
            int64_t j = k < dim ? s.i[k] + d : (d == 0 ? 0 : -1);
            if (k < dim && (j < 0 || j >= R->n[k]))
                j = !R->periodic[k] ? -1 /* beyond a wall: no cell */
                                    : (j < 0 ? j + R->n[k] : j - R->n[k]); /* n >= 2D + 1 */
            c[k][d + D] = j;
        }
    /* the entry's rows as in the inner case, each with its wrapped or dropped
     * (y, z) cell; a row's words one by one only where x wraps or meets a wall */
    const int W = 2 * D + 1;
    const int x_whole = s.i[0] - D >= 0 && s.i[0] + D < R->n[0];
    for (uint32_t m = rows; m; m &= m - 1) {
        const int r = __builtin_ctz(m);
        const int64_t cy = c[1][dim == 3 ? r % W : r], cz = c[2][dim == 3 ? r / W : D];
        if ((cy | cz) < 0)
            continue;
        uint64_t *row = &R->covered[(uint64_t)(cz * R->n[1] + cy) * (uint64_t)R->n[0]];
        const uint64_t *src = w + r * W;
        if (x_whole) {
            or_row(row + s.i[0] - D, src, D);
            continue;
        }
        for (int q = 0; q < W; q++)
            if (c[0][q] >= 0)
                row[c[0][q]] |= src[q];
    }
}

void pk_rsa_region_mark(pk_rsa_region *R, const double *x)
{
    pk_rsa_region_mark_at(R, pk_rsa_region_locate(R, x));
}
