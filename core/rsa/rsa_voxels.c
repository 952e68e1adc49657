/* rsa_voxels.c — the voxel set of space not yet known to be covered, for the
 * one-grain-at-a-time path.  Contract: rsa_voxels.h. */
#include "rsa_voxels.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* list entries voxel·8 + group fit 32 bits */
#define MAX_VOXELS ((uint64_t)1 << 29)
/* The list is compacted once 1/STALE_PER_LIST of its groups are full: draws
 * into those are certain rejections, a compaction is one pass over the list.
 * 2: TODO */
#define STALE_PER_LIST 2

/* Groups are listed instead of voxels once there are at most this many open
 * ones per listed voxel: a draw then lands in an open sub-voxel
 * 8/GROUPS_PER_VOXEL times as often, for a list at most this many times as
 * long.  2: A16 Δd 1 mm at 10⁵ grains, the same CPU time as groups all along with 55 MB instead of 82 (docs/perf/rsa-gap.md) */
#define GROUPS_PER_VOXEL 2

/* Voxel edge: the diagonal of the smallest contact distance 2 r_valid + Δd
 * (64 sub-voxels of a quarter (3D) or an eighth (2D) of it resolve the
 * marks; rsa_voxels.h). */
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

/* Groups of 2×2×2 (3D) or 4×2 (2D) sub-voxels, one byte each: a pocket of
 * open space a few sub-voxels wide keeps only its groups listed. */
static void set_bit_layout(pk_rsa_vox *v)
{
    for (int l = 0; l < v->sub; l++) {
        if (v->box.dim == 3) {
            v->boff[0][l] = (uint8_t)((l >> 1) * 8 + (l & 1));
            v->boff[1][l] = (uint8_t)((l >> 1) * 16 + (l & 1) * 2);
            v->boff[2][l] = (uint8_t)((l >> 1) * 32 + (l & 1) * 4);
        } else {
            v->boff[0][l] = (uint8_t)((l >> 2) * 8 + (l & 3));
            v->boff[1][l] = (uint8_t)((l >> 1) * 16 + (l & 1) * 4);
        }
    }
    int S = v->sub, Sz = v->box.dim == 3 ? S : 1;
    for (unsigned m = 0; m < (1u << S); m++) {
        v->row_bits[m] = 0;
        for (int lx = 0; lx < S; lx++)
            if (m >> lx & 1)
                v->row_bits[m] |= (uint64_t)1 << v->boff[0][lx];
    }
    for (int lz = 0; lz < Sz; lz++)
        for (int ly = 0; ly < S; ly++)
            for (int lx = 0; lx < S; lx++) {
                unsigned bit = v->boff[0][lx] + v->boff[1][ly] + v->boff[2][lz];
                v->lsub[bit][0] = (uint8_t)lx;
                v->lsub[bit][1] = (uint8_t)ly;
                v->lsub[bit][2] = (uint8_t)lz;
            }
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
    v->sub = b->dim == 3 ? 4 : 8; /* 4³ or 8² sub-voxels: one 64-bit word */
    for (int k = 0; k < PK_MAXDIM; k++)
        v->se[k] = v->e[k] / (double)v->sub;
    set_bit_layout(v);
    /* zeroed pages are mapped on first touch: no pass over the voxels here,
     * and the list is the identity until its first compaction */
    v->covered = calloc(nv, sizeof *v->covered);
    if (!v->covered) {
        pk_rsa_vox_free(v);
        return -1;
    }
    v->nlist = nv;
    v->open_groups = nv * PK_RSA_VOX_GROUPS;
    return 0;
}

void pk_rsa_vox_free(pk_rsa_vox *v)
{
    free(v->covered);
    free(v->list);

    memset(v, 0, sizeof *v);
}

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

static inline int group_open(const pk_rsa_vox *v, uint32_t e)
{
    return (uint8_t)(v->covered[e >> 3] >> (8 * (e & 7))) != 0xff;
}

/* Bytes of w with all 8 bits set (exact: no carry crosses a byte). */
static inline int full_bytes(uint64_t w)
{
    const uint64_t lo7 = 0x7f7f7f7f7f7f7f7full;
    uint64_t t = ~w;
    uint64_t y = ~(((t & lo7) + lo7) | t | lo7) >> 7; /* 1 in each full byte */
    return (int)((y * 0x0101010101010101ull) >> 56);
}

/* The listed voxels turn into a list of their open groups, no longer than
 * theirs.  Draws picked from the voxel list are dropped (rejected
 * whatever their place: the law of the others is kept). */
static void list_groups(pk_rsa_vox *v)
{
    uint32_t *g = malloc((v->open_groups + 1) * sizeof *g);
    if (!g)
        return; /* draws stay on voxels */
    uint64_t k = 0;
    for (uint64_t i = 0; i < v->nlist; i++) {
        uint32_t vox = v->list ? v->list[i] : (uint32_t)i;
        for (uint32_t q = 0; q < PK_RSA_VOX_GROUPS; q++)
            if (group_open(v, vox * PK_RSA_VOX_GROUPS + q))
                g[k++] = vox * PK_RSA_VOX_GROUPS + q;
    }
    free(v->list);
    v->list = g;
    v->nlist = k;
    v->nstale = 0;
    v->grouped = 1;
    /* every pending draw is dropped, looked up or not: a pick not yet looked
     * up is uniform over the voxel list's length, and the group list may be
     * longer (up to GROUPS_PER_VOXEL times) — it would reach only its front */
    for (int s = 0; s < PK_RSA_DRAW_AHEAD; s++)
        v->pick[s] = v->id[s] = UINT32_MAX;
}

/* Drop the voxels (groups) left without an open sub-voxel from the list (in
 * place, in list order, so the bits are read as a stream); the first
 * compaction makes the list.  Once the open groups are fewer than half the
 * listed voxels, groups are listed instead (4 bytes a voxel at most). */
static void compact(pk_rsa_vox *v)
{
    if (!v->grouped && v->open_groups <= GROUPS_PER_VOXEL * v->nlist) {
        list_groups(v);
        if (v->grouped)
            return;
    }
    uint64_t k = 0;
    if (!v->list) {
        v->list = malloc((v->nlist - v->nstale + 1) * sizeof *v->list);
        if (!v->list)
            return; /* draws stay on the identity list */
        for (uint64_t i = 0; i < v->nlist; i++)
            if (~v->covered[i])
                v->list[k++] = (uint32_t)i;
    } else if (!v->grouped) {
        for (uint64_t i = 0; i < v->nlist; i++)
            if (~v->covered[v->list[i]])
                v->list[k++] = v->list[i];
    } else {
        for (uint64_t i = 0; i < v->nlist; i++)
            if (group_open(v, v->list[i]))
                v->list[k++] = v->list[i];
    }
    v->nlist = k;
    v->nstale = 0;
}

/* Squared distance from c to the nearest point of voxel interval i on axis k. */
static inline double near2(const pk_rsa_vox *v, int k, int64_t i, double c)
{
    double a = v->org[k] + v->e[k] * (double)i;
    double f = c < a ? a - c : (c > a + v->e[k] ? c - a - v->e[k] : 0);
    return f * f;
}

/* Squared distance from c to the farthest point of voxel interval i on axis k. */
static inline double far2(const pk_rsa_vox *v, int k, int64_t i, double c)
{
    double a = v->org[k] + v->e[k] * (double)i;
    double d = c < a + 0.5 * v->e[k] ? a + v->e[k] - c : c - a;
    return d * d;
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

/* The sub-voxels of one voxel whose farthest corners are inside the ball
 * (squared far distances per axis fx, fy, fz): a row along x is all out when
 * its nearest far corner is, all in when its farthest is, else its bits
 * come from the row's mask (rows are most of the boundary voxels' cost). */
static inline uint64_t cover_word(const pk_rsa_vox *v, const double *fx, const double *fy,
                                  const double *fz, double R2, int S, int Sz)
{
    double xmin = fx[0], xmax = fx[0];
    for (int lx = 1; lx < S; lx++) {
        xmin = fx[lx] < xmin ? fx[lx] : xmin; /* fmin/fmax are libm calls at -O2 */
        xmax = fx[lx] > xmax ? fx[lx] : xmax;
    }
    uint64_t covered = 0;
    for (int lz = 0; lz < Sz; lz++)
        for (int ly = 0; ly < S; ly++) {
            double rem = R2 - fz[lz] - fy[ly];
            if (!(xmin <= rem))
                continue;
            unsigned row = (unsigned)v->boff[2][lz] + v->boff[1][ly];
            unsigned m = (1u << S) - 1;
            if (!(xmax <= rem)) {
                m = 0;
                for (int lx = 0; lx < S; lx++)
                    m |= (unsigned)(fx[lx] <= rem) << lx;
            }
            covered |= v->row_bits[m] << row;
        }
    return covered;
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
    /* the rows' words are far apart: fetch them all before the work (the
     * loads were most of this function's time) */
    for (int64_t iz = zlo; iz <= zhi; iz++) {
        uint64_t zbase = (uint64_t)wrap_index(v, 2, iz) * (uint64_t)v->n[1];
        for (int64_t iy = ylo; iy <= yhi; iy++) {
            const uint64_t *row =
                &v->covered[(zbase + (uint64_t)wrap_index(v, 1, iy)) * (uint64_t)v->n[0]];
            __builtin_prefetch(&row[wrap_index(v, 0, xlo)]);
            __builtin_prefetch(&row[wrap_index(v, 0, xhi)]);
        }
    }
    double fz[8] = {0}, fy[8], fx[8];
    for (int64_t iz = zlo; iz <= zhi; iz++) {
        double nz = dim == 3 ? near2(v, 2, iz, x[2]) : 0;
        if (nz >= R2)
            continue;
        double fz_all = dim == 3 ? far2(v, 2, iz, x[2]) : 0;
        if (dim == 3)
            sub_far2(v, 2, iz, x[2], fz);
        uint64_t zbase = (uint64_t)wrap_index(v, 2, iz) * (uint64_t)v->n[1];
        for (int64_t iy = ylo; iy <= yhi; iy++) {
            double nzy = nz + near2(v, 1, iy, x[1]);
            if (nzy >= R2)
                continue;
            sub_far2(v, 1, iy, x[1], fy);
            uint64_t base = (zbase + (uint64_t)wrap_index(v, 1, iy)) * (uint64_t)v->n[0];
            double fzy = fz_all + far2(v, 1, iy, x[1]);
            for (int64_t ix = xlo; ix <= xhi; ix++) {
                if (nzy + near2(v, 0, ix, x[0]) >= R2)
                    continue;
                uint64_t vid = base + (uint64_t)wrap_index(v, 0, ix);
                uint64_t was = v->covered[vid];
                if (!~was)
                    continue;
                if (fzy + far2(v, 0, ix, x[0]) <= R2) { /* the whole voxel is inside */
                    v->covered[vid] = ~(uint64_t)0;
                    uint64_t filled = (uint64_t)(PK_RSA_VOX_GROUPS - full_bytes(was));
                    v->open_groups -= filled;
                    v->nstale += v->grouped ? filled : 1;
                    continue;
                }
                sub_far2(v, 0, ix, x[0], fx);
                uint64_t covered = cover_word(v, fx, fy, fz, R2, S, Sz);
                if (covered & ~was) {
                    uint64_t now = was | covered;
                    v->covered[vid] = now;
                    uint64_t filled = (uint64_t)(full_bytes(now) - full_bytes(was));
                    v->open_groups -= filled;
                    v->nstale += v->grouped ? filled : (uint64_t) !~now;
                }
            }
        }
    }
    if (v->nstale * STALE_PER_LIST > v->nlist ||
        (!v->grouped && v->open_groups <= GROUPS_PER_VOXEL * v->nlist))
        compact(v);
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

/* Draws are picked DRAW_AHEAD calls before their use and their group is
 * looked up halfway, so the two cache misses of a draw (list entry, bits)
 * overlap with other draws' work.  Still exact: a pick is uniform over the
 * list when made; if it lies beyond the list's end at the look-up (a
 * compaction since) it is a rejected draw, otherwise its voxel is uniform
 * over the list of that moment, whose open space contains all space still
 * open at the use, where the bits and the exact test are applied.  8: TODO */
static inline void pick(pk_rsa_vox *v, pk_rng *g, int s)
{
    v->pick[s] = (uint32_t)uniform_below(g, (uint32_t)v->nlist);
    if (v->list)
        __builtin_prefetch(&v->list[v->pick[s]]);
}

static inline void look_up(pk_rsa_vox *v, int s)
{
    uint32_t k = v->pick[s];
    v->id[s] = k >= v->nlist ? UINT32_MAX : (v->list ? v->list[k] : k);
    if (v->id[s] != UINT32_MAX)
        __builtin_prefetch(&v->covered[v->grouped ? v->id[s] >> 3 : v->id[s]]);
}

int pk_rsa_vox_draw(pk_rsa_vox *v, pk_rng *g, double x[PK_MAXDIM])
{
    if (v->nlist == 0)
        return -1;
    if (!v->primed) {
        for (int s = 0; s < PK_RSA_DRAW_AHEAD; s++)
            pick(v, g, s);
        for (int s = 0; s < PK_RSA_DRAW_AHEAD / 2; s++)
            look_up(v, s);
        v->primed = 1;
    }
    int h = v->head;
    v->head = (h + 1) % PK_RSA_DRAW_AHEAD;
    uint64_t id = v->id[h];
    pick(v, g, h);
    look_up(v, (h + PK_RSA_DRAW_AHEAD / 2) % PK_RSA_DRAW_AHEAD);
    if (id == UINT32_MAX)
        return 1; /* past the list's end: a compaction dropped its group */
    /* a uniform sub-voxel of the group's 8, or of the voxel's 64 */
    uint64_t t = v->grouped ? id >> 3 : id;
    unsigned bit = v->grouped ? (unsigned)(id & 7) * 8 + (unsigned)(pk_rng_next(g) >> 61)
                              : (unsigned)(pk_rng_next(g) >> 58);
    if (v->covered[t] >> bit & 1)
        return 1; /* covered sub-voxel: the exact test would reject any point in it */
    x[2] = 0;
    for (int k = 0; k < v->box.dim; k++) {
        int64_t i = (int64_t)(t % (uint64_t)v->n[k]);
        t /= (uint64_t)v->n[k];
        int64_t j = i * v->sub + v->lsub[bit][k];
        x[k] = v->org[k] + v->se[k] * ((double)j + pk_rng_uniform(g));
    }
    return 0;
}
