/* rsa_batch.c — batched RSA for runs of equal grains: draw, filter against the
 * cell store, walk in attempt order, store.  Contract: rsa_batch.h, README.md. */
#include "rsa_batch.h"
#include "core/base/rng.h"

#include <stdlib.h>
#include <string.h>

#include "rsa_cells.h"
#include "rsa_region.h"

/* The tuned constants below: what each was measured against, docs/perf/rsa.md. */
/* Batch size: B = SURVIVORS / (survivors per draw of the last batch) draws,
 * between B_MIN and B_MAX: a batch's scratch stays in the per-core cache
 * (docs/perf/rsa.md: mono3d_phi030_1e4..1e6, 1.19 M/s at 10^6). */
#define B_MIN 4096
#define B_MAX ((size_t)1 << 20)
#define SURVIVORS 512.0
/* Prefetch distance of the region draws' list and mark look-ups (draws; the
 * draw arrays have this much slack: no bound tests in the look-up loop;
 * mono3d_phi030_1e6: +2 % over 64). */
#define PICK_AHEAD 128
/* Counting sort of attempts by cell: at most this many buckets (contiguous
 * ranges of cell indices), so the scatter writes few streams. */
#define MAX_BUCKETS 4096
/* The store may not be much larger than the run needs (a few fine grains in
 * a huge box keep the per-grain path). */
#define CELLS_PER_GRAIN 64
#define CELLS_FREE 65536
/* Draws come from the open region once a batch accepted fewer than this
 * fraction of its draws and at least REGION_MIN_LEFT grains remain (equal
 * spheres: from φ ≈ 0.2 on). */
#define REGION_SWITCH_ACC 0.2
#define REGION_MIN_LEFT 256
/* Compact the open list once the draws into fully covered cells since the
 * last compaction cost about one pass over it (a stale draw ≈ this many list
 * entries; 10^6 grains: three compactions, 15.6 draws per grain). */
#define STALE_PER_PASS 16
/* Region cells per store cell and axis: edge ≈ c/2, fine voxels ≈ c/8 in 3D
 * (c/16 in 2D); at most REGION_CELLS_PER_GRAIN region cells per grain of the
 * run (12 bytes each). */
#define REGION_SPLIT 2
#define REGION_CELLS_PER_GRAIN 64
/* Obstacles of other sizes (grains placed before the run) are marked only
 * while their exclusion radius is at most this many contact distances (the
 * cost grows with its square; unmarked obstacles only cost draws). */
#define REGION_MAX_OBSTACLE 3.0
/* Steps of the mark table per axis: cbrt(m / REGION_GRAINS_PER_ENTRY) for a
 * run of m grains, at least REGION_STEPS_MIN, at most PK_RSA_REGION_MAX_STEPS
 * (finer steps mark more, but each entry costs ~40 000 instructions). */
#define REGION_STEPS_MIN 6
#define REGION_GRAINS_PER_ENTRY 128.0

/* 1 if a cell store for grains of radius r over this draw range serves the
 * box and stays O(m) for a run of m grains; decided without drawing. */
static int usable(const pk_box *b, double r, double gap, const double *span, size_t m)
{
    uint64_t nc = pk_rsa_cells_count(b, r, gap, span);
    return nc > 0 && nc <= (uint64_t)CELLS_PER_GRAIN * m + CELLS_FREE;
}

typedef struct scratch {
    size_t cap;      /* attempts */
    size_t capd;     /* region draws (rpos, rbit) */
    double *pos;     /* [cap][3] attempts in attempt order */
    uint32_t *rpos;  /* region draws: list position of each draw, then the cell of
                           each draw not rejected at once (in draw order) */
    uint8_t *rbit;   /* its fine voxel (same order as rpos) */
    uint32_t *rdraw; /* draw number of each draw not rejected at once */
    uint32_t *ord;   /* [cap + 1] draw number of each attempt in its batch
                           (region draws: certain rejections make no attempt) */
    uint32_t *key;   /* bucket of each attempt */
    double *spos;    /* [cap][3] attempts' offsets from their cells' corners
                           (pk_rsa_cells_key_q) in bucket order */
    uint32_t *sidx;  /* attempt index of each sorted entry */
    uint32_t *skey;  /* its cell key */
    uint32_t *kept;  /* sorted positions of the survivors of step 2 */
    uint64_t *sbit;  /* bit a: attempt a survived step 2 */
    int32_t *slot;   /* survivor number of attempt a (set where sbit is) */
    double *surv;    /* [cap][3] survivors in sorted order (before step 2: the
                           attempts' offsets in attempt order) */
    uint32_t *vkey;  /* survivors' keys */
    uint8_t *taken;  /* survivor accepted in step 3 */
    uint32_t *pid;   /* its index in the particle array (set where taken is) */
    uint32_t *count; /* [MAX_BUCKETS + 1] */
    size_t stale;    /* region draws of the last batch that fell in a fully covered cell */
    /* step 3: hash of the batch's accepted survivors by cell */
    int32_t *head;   /* [power of two >= 2 cap] */
    int32_t *hnext;  /* per survivor */
    uint64_t *hcell; /* per survivor: its cell */
} scratch;

static void scratch_free(scratch *w)
{
    free(w->pos);
    free(w->ord);
    free(w->rpos);
    free(w->rbit);
    free(w->rdraw);
    free(w->key);
    free(w->spos);
    free(w->sidx);
    free(w->skey);
    free(w->kept);
    free(w->sbit);
    free(w->slot);
    free(w->surv);
    free(w->vkey);
    free(w->taken);
    free(w->pid);
    free(w->count);
    free(w->head);
    free(w->hnext);
    free(w->hcell);
    memset(w, 0, sizeof *w);
}

/* Scratch holds nothing from one batch to the next, so a larger block
 * replaces the old one without realloc's copy (free, then malloc: the heap
 * can hand back pages just freed).  NULL and *fail set when out of memory
 * (scratch_free still works). */
static void *renew(void *p, size_t bytes, int *fail)
{
    free(p);
    void *q = malloc(bytes ? bytes : 1);
    if (!q)
        *fail = 1;
    return q;
}

/* Capacity for a request of n: at least twice the last, so few renewals. */
static size_t grown(size_t cap, size_t n) { return n > 2 * cap ? n : 2 * cap; }

/* Room for region batches of B draws (grows only, contents not kept; -1 when
 * out of memory). */
static int scratch_reserve_draws(scratch *w, size_t B)
{
    if (B <= w->capd)
        return 0;
    B = grown(w->capd, B);
    int fail = 0;
    w->rpos = renew(w->rpos, (B + PICK_AHEAD) * sizeof *w->rpos, &fail);
    w->rbit = renew(w->rbit, B, &fail);
    w->rdraw = renew(w->rdraw, B * sizeof *w->rdraw, &fail);
    w->capd = fail ? 0 : B; /* (a failed renewal leaves NULLs: room for nothing) */
    if (fail)
        return -1;
    return 0;
}

/* Room for batches of B attempts (grows only, contents not kept; -1 when out
 * of memory). */
static int scratch_reserve(scratch *w, size_t B)
{
    if (B <= w->cap)
        return 0;
    B = grown(w->cap, B);
    uint64_t hb = 64;
    while (hb < 2 * (uint64_t)B)
        hb <<= 1;
    int fail = 0;
    w->pos = renew(w->pos, 3 * B * sizeof *w->pos, &fail);
    w->ord = renew(w->ord, (B + 1) * sizeof *w->ord, &fail);
    w->key = renew(w->key, B * sizeof *w->key, &fail);
    w->spos = renew(w->spos, 3 * B * sizeof *w->spos, &fail);
    w->sidx = renew(w->sidx, B * sizeof *w->sidx, &fail);
    w->skey = renew(w->skey, B * sizeof *w->skey, &fail);
    w->kept = renew(w->kept, B * sizeof *w->kept, &fail);
    w->sbit = renew(w->sbit, (B / 64 + 1) * sizeof *w->sbit, &fail);
    w->slot = renew(w->slot, B * sizeof *w->slot, &fail);
    w->surv = renew(w->surv, 3 * B * sizeof *w->surv, &fail);
    w->vkey = renew(w->vkey, B * sizeof *w->vkey, &fail);
    w->taken = renew(w->taken, B, &fail);
    w->pid = renew(w->pid, B * sizeof *w->pid, &fail);
    w->count = renew(w->count, (MAX_BUCKETS + 1) * sizeof *w->count, &fail);
    w->head = renew(w->head, hb * sizeof *w->head, &fail);
    w->hnext = renew(w->hnext, B * sizeof *w->hnext, &fail);
    w->hcell = renew(w->hcell, B * sizeof *w->hcell, &fail);
    w->cap = fail ? 0 : B;
    if (fail)
        return -1;
    return 0;
}

static inline uint64_t hash_cell(uint64_t lin, uint64_t mask)
{
    return (lin * 0x9E3779B97F4A7C15ull) >> 20 & mask;
}

/* The batch's occupancy map: bit lin is set while a survivor accepted in
 * this batch lies in (real) cell lin — most survivors have no such neighbour,
 * and 9 (3D) reads of three adjacent bits say so without hashing. */
static inline int occupied(const uint8_t *map, uint64_t lin)
{
    return map[lin >> 3] >> (lin & 7) & 1;
}

/* Step 3's test: is survivor x (key: pk_rsa_cells_key_q) within contact of a
 * survivor accepted earlier in this batch?  Off the seams the neighbours are
 * the fixed offsets of the filter; ghost cells never match a stored cell. */
static int batch_hits(const pk_rsa_cells *C, const scratch *w, const uint8_t *map, uint64_t hmask,
                      const double *x, uint32_t key)
{
    uint64_t nb[27];
    int m;
    if (pk_rsa_cells_seam(C, x)) {
        m = pk_rsa_cells_around(C, x, nb);
    } else {
        const uint64_t lin = pk_rsa_cells_index(key);
        unsigned any = 0;
        for (int r = 0; r < C->nrow; r++)
            any |= pk_rsa_cells_bits3(map, lin + (uint64_t)C->row[r]);
        if (!any)
            return 0;
        const int64_t *off = C->off[pk_rsa_cells_octant(key)];
        for (int q = 0; q < C->noff; q++)
            nb[q] = (uint64_t)((int64_t)lin + off[q]);
        m = C->noff;
    }
    for (int q = 0; q < m; q++)
        for (int32_t j = occupied(map, nb[q]) ? w->head[hash_cell(nb[q], hmask)] : -1; j >= 0;
             j = w->hnext[j])
            if (w->hcell[j] == nb[q] && pk_rsa_cells_close(C, &w->surv[3 * (size_t)j], x))
                return 1;
    return 0;
}

/* Prefetch distance of the marks of step 4 and region_start (grains;
 * mono3d_phi030_1e6: -6 % time). */
#define MARK_AHEAD 4
/* Marks in flight: grain q + MARK_AHEAD is located (once: the prefetch and
 * the mark share its spot) and its words fetched while grain q is marked. */
#define MARK_RING 8 /* a power of two > MARK_AHEAD */

static inline void mark_ahead(pk_rsa_region *reg, pk_rsa_region_spot *ring, size_t q,
                              const double *x)
{
    pk_rsa_region_spot *s = &ring[q % MARK_RING];
    *s = pk_rsa_region_locate(reg, x);
    pk_rsa_region_prefetch(reg, *s);
}
/* Prefetch distance of the centres region_start marks (grains: they come in
 * cell order from the store, each a miss in the particle array; with the
 * marks' rows fetched ahead, mono3d_phi030_1e6: -9..11 % CPU). */
#define START_AHEAD 16
/* Prefetch distance of step 4's store records (grains; mono3d_phi030_1e6:
 * -4..6 % CPU). */
#define INSERT_AHEAD 8

/* Region draws, step 1a: pick B (cell, fine voxel) pairs, then look their
 * marks up, dropping the certain rejections: for a below the number returned,
 * draw w->rdraw[a] was not rejected at once; cell w->rpos[a], fine voxel
 * w->rbit[a].  A batch's draws are far sparser than the cache lines of the list
 * and of the marks, so each look-up is two misses; fetched ahead (the mark's
 * address needs the list entry fetched earlier) they overlap. */
static size_t region_pick(const pk_rsa_region *reg, scratch *w, size_t B, pk_rng *rng)
{
    pk_rng g0 = *rng, *g = &g0; /* a local copy: in registers, whatever the stores below */
    for (size_t d = 0; d < B; d++) {
        unsigned bit;
        w->rpos[d] = pk_rsa_region_pick(reg, g, &bit);
        w->rbit[d] = (uint8_t)bit;
    }
    *rng = g0;
    memset(&w->rpos[B], 0, PICK_AHEAD * sizeof *w->rpos); /* the look-ahead past the end:
                                                             list position 0, harmless */
    const uint32_t *list = reg->list;
    const uint64_t *covered = reg->covered;
    size_t open = 0, stale = 0;
    for (size_t d = 0; d < B; d++) {
        __builtin_prefetch(&list[w->rpos[d + PICK_AHEAD]]);
        __builtin_prefetch(&covered[list[w->rpos[d + PICK_AHEAD / 2]]]);
        const uint32_t cell = list[w->rpos[d]];
        const unsigned bit = w->rbit[d];
        /* (open <= d: the entries written here are read no more) */
        w->rpos[open] = cell;
        w->rbit[open] = (uint8_t)bit;
        w->rdraw[open] = (uint32_t)d;
        const uint64_t word = covered[cell];
        open += !(word >> bit & 1);
        stale += word == ~(uint64_t)0;
    }
    w->stale = stale;
    return open;
}

/* Steps 1–2 for B draws: draw, sort by cell bucket, filter against the
 * store.  Plain draws make B attempts; region draws (reg != NULL) skip the
 * certain rejections: *A attempts, w->ord[a] the draw number of attempt a,
 * w->ord[*A] = B.  Returns the number of survivors, SIZE_MAX when out of
 * memory. */
static size_t draw_and_filter(const pk_rsa_cells *C, const double *px, scratch *w, size_t B,
                              int dim, const double *lo, const double *span, pk_rng *rng, int shift,
                              uint32_t nbucket, const pk_rsa_region *reg, size_t *A)
{
    size_t open = 0;
    if (reg) { /* the certain rejections need no room beyond the draw arrays */
        if (scratch_reserve_draws(w, B) != 0)
            return SIZE_MAX;
        open = region_pick(reg, w, B, rng);
        if (scratch_reserve(w, open) != 0)
            return SIZE_MAX;
    } else if (scratch_reserve(w, B) != 0) {
        return SIZE_MAX;
    }
    const double lo0 = lo[0], lo1 = lo[1], lo2 = lo[2], sp0 = span[0], sp1 = span[1];
    const double sp2 = dim == 3 ? span[2] : 0;
    /* local copies: the stores below cannot alias them, so the generator state
     * and the store's geometry stay in registers */
    pk_rng g = *rng;
    const pk_rsa_cells K = *C;
    double *restrict pos = w->pos, *restrict qpos = w->surv;
    uint32_t *restrict keys = w->key, *restrict ord = w->ord;
    size_t a = 0;
    if (reg) {
        for (; a < open; a++) {
            double x[3];
            pk_rsa_region_point(reg, w->rpos[a], w->rbit[a], &g, x);
            memcpy(&pos[3 * a], x, sizeof x);
            keys[a] = pk_rsa_cells_key_q(&K, x, &qpos[3 * a]);
            ord[a] = w->rdraw[a];
        }
        ord[a] = (uint32_t)B;
    } else {
        for (; a < B; a++) {
            /* rsa.c's plain draw: x[k] = lo[k] + span[k]·u, k = 0, 1 (, 2), z = 0 in 2D */
            double x[3];
            x[0] = lo0 + sp0 * pk_rng_uniform(&g);
            x[1] = lo1 + sp1 * pk_rng_uniform(&g);
            x[2] = dim == 3 ? lo2 + sp2 * pk_rng_uniform(&g) : 0;
            memcpy(&pos[3 * a], x, sizeof x);
            keys[a] = pk_rsa_cells_key_q(&K, x, &qpos[3 * a]);
        }
    }
    *rng = g;
    *A = a;
    /* the counts of the cell buckets */
    memset(w->count, 0, (nbucket + 1) * sizeof *w->count);
    for (size_t q = 0; q < a; q++)
        w->count[(pk_rsa_cells_index(w->key[q]) >> shift) + 1]++;
    B = a; /* from here on: attempts */
    for (uint32_t k = 0; k < nbucket; k++)
        w->count[k + 1] += w->count[k];
    for (size_t q = 0; q < B; q++) {
        uint32_t key = w->key[q];
        uint32_t t = w->count[pk_rsa_cells_index(key) >> shift]++;
        memcpy(&w->spos[3 * (size_t)t], &w->surv[3 * q], 3 * sizeof(double)); /* offsets */
        w->sidx[t] = (uint32_t)q;
        w->skey[t] = key;
    }
    size_t S = pk_rsa_cells_filter(C, px, w->spos, w->pos, w->sidx, w->skey, B, w->kept);
    memset(w->sbit, 0, (B / 64 + 1) * sizeof *w->sbit);
    for (size_t j = 0; j < S; j++) {
        uint32_t t = w->kept[j], q = w->sidx[t];
        memcpy(&w->surv[3 * j], &w->pos[3 * (size_t)q], 3 * sizeof(double));
        w->vkey[j] = w->skey[t];
        w->slot[q] = (int32_t)j;
        w->sbit[q >> 6] |= (uint64_t)1 << (q & 63);
    }
    return S;
}

/* Mark the exclusion balls of the grains placed so far (the run's with radius
 * c, earlier obstacles with r + r_j + Δd when not too wide) and list the cells
 * left open.  -1 when out of memory (the run then keeps plain draws).  Marks
 * are optional for correctness: a cancel request cuts the marking short. */
static int region_start(pk_rsa_region *reg, const pk_rsa_cells *C, const pk_box *b, double r,
                        double gap, const double *lo, const double *span, const pk_particles *out,
                        size_t first, size_t m, pk_monitor *mon, pk_progress *pg)
{
    const double c = 2 * r + gap;
    uint64_t cells = 1;
    for (int k = 0; k < b->dim; k++)
        cells *= REGION_SPLIT * (uint64_t)C->n[k];
    if (cells > REGION_CELLS_PER_GRAIN * (uint64_t)m + CELLS_FREE)
        return -1; /* a sparse run: not worth the memory */
    int64_t n[PK_MAXDIM];
    for (int k = 0; k < PK_MAXDIM; k++)
        n[k] = k < b->dim ? REGION_SPLIT * C->n[k] : 1;
    int steps = (int)cbrt((double)m / REGION_GRAINS_PER_ENTRY);
    if (steps < REGION_STEPS_MIN)
        steps = REGION_STEPS_MIN;
    if (steps > PK_RSA_REGION_MAX_STEPS)
        steps = PK_RSA_REGION_MAX_STEPS;
    if (pk_rsa_region_init(reg, b, n, lo, span, c, steps) != 0)
        return -1;
    for (size_t j = 0; j < first; j++) { /* obstacles of other sizes */
        double rad = r + out->r[j] + gap;
        if (rad <= REGION_MAX_OBSTACLE * c)
            pk_rsa_region_cover(reg, &out->x[3 * j], rad);
        if ((j & 0xfff) == 0xfff && pk_monitor_tick(mon, pg, 0))
            break;
    }
    /* the run's grains from the store, in cell order (neighbouring marks share
     * cache lines; in placement order each mark would miss on large runs),
     * listed first so that each grain's centre and its mark's rows can be
     * fetched ahead (START_AHEAD, MARK_AHEAD grains) */
    size_t k = 0;
    uint32_t *ids = malloc((out->n - first + 1) * sizeof *ids); /* (+1: never malloc(0)) */
    if (!ids) {
        pk_rsa_region_free(reg);
        return -1;
    }
    for (int64_t z = 0; z < C->n[2]; z++)
        for (int64_t y = 0; y < C->n[1]; y++) {
            const pk_rsa_cell1 *row =
                &C->cell[C->base + (uint64_t)z * C->stride[2] + (uint64_t)y * C->stride[1]];
            for (int64_t x = 0; x < C->n[0]; x++) {
                const uint32_t a = row[x].id;
                if (a == PK_RSA_CELLS_NONE)
                    continue;
                if (!(a & PK_RSA_CELLS_MORE))
                    ids[k++] = a;
                else
                    for (int32_t e = (int32_t)(a & PK_RSA_CELLS_POOL); e >= 0; e = C->extra[e].next)
                        ids[k++] = C->extra[e].id;
            }
        }
    pk_rsa_region_spot ring[MARK_RING];
    for (size_t q = 0; q < k && q < MARK_AHEAD; q++)
        mark_ahead(reg, ring, q, &out->x[3 * (size_t)ids[q]]);
    for (size_t q = 0; q < k && !(mon && mon->cancelled); q++) {
        if (q + START_AHEAD < k)
            __builtin_prefetch(&out->x[3 * (size_t)ids[q + START_AHEAD]]);
        if (q + MARK_AHEAD < k)
            mark_ahead(reg, ring, q + MARK_AHEAD, &out->x[3 * (size_t)ids[q + MARK_AHEAD]]);
        pk_rsa_region_mark_at(reg, ring[q % MARK_RING]);
        if ((q & 0xfff) == 0xfff)
            pk_monitor_tick(mon, pg, 0);
    }
    free(ids);
    pk_rsa_region_compact(reg);
    return 0;
}

/* Draw number of attempt a (plain draws: every draw is an attempt). */
static inline size_t draw_of(const scratch *w, int region, size_t a)
{
    return region ? w->ord[a] : a;
}

/* One run of run_batches: the cell store, the batch scratch, the occupancy
 * map of the batch's placements and the open region, with the counters
 * carried from one batch to the next. */
typedef struct batch_run {
    const pk_rsa_batch_env *e;
    double r;
    const int32_t *species;
    size_t m;
    const double *lo, *span;
    pk_rsa_cells C;
    scratch w;
    uint8_t *map;     /* cells holding a grain accepted in this batch (bit per cell) */
    int shift;        /* bucket of a cell: its index >> shift */
    uint32_t nbucket; /* buckets of the counting sort */
    int grid_empty;   /* no grain in the grid: its overlap test is skipped */
    double ball;      /* measure of one grain */
    size_t first;     /* grains before the run (obstacles) */
    pk_rsa_region reg;
    int region, region_allowed; /* draws from the open region; may still switch to it */
    uint64_t stale_since;       /* draws in fully covered cells since the last compaction */
    size_t placed;
    uint64_t failed;      /* draws failed in a row */
    double p_surv, p_acc; /* running estimates from the last batch */
} batch_run;

/* Set up the run's store, scratch and map.  -1 when out of memory (nothing
 * left to free). */
static int open_run(batch_run *u, const pk_rsa_batch_env *e, double r, const int32_t *species,
                    size_t m, const double *lo, const double *span)
{
    *u = (batch_run){.e = e, .r = r, .species = species, .m = m, .lo = lo, .span = span};
    if (pk_rsa_cells_init(&u->C, e->b, r, e->prm->delta_d, lo, span) != 0)
        return -1;
    u->map = calloc(u->C.ncell / 8 + 16, 1);
    if (!u->map) {
        pk_rsa_cells_free(&u->C);
        return -1;
    }
    while (((u->C.ncell - 1) >> u->shift) >= MAX_BUCKETS)
        u->shift++;
    u->nbucket = (uint32_t)((u->C.ncell - 1) >> u->shift) + 1;
    u->grid_empty = 1;
    for (int l = 0; l < e->grid->nlevel; l++)
        u->grid_empty &= e->grid->lv[l].count == 0;
    u->ball = pk_ball_measure(e->b->dim, r);
    u->first = e->out->n;
    u->region_allowed = e->prm->draws == PK_RSA_DRAWS_OPEN;
    u->p_surv = u->p_acc = 1;
    return 0;
}

static void close_run(batch_run *u)
{
    pk_rsa_region_free(&u->reg);
    scratch_free(&u->w);
    free(u->map);
    pk_rsa_cells_free(&u->C);
}

/* Attempts of the next batch: enough draws for SURVIVORS survivors, at most
 * twice what the grains left need at the last acceptance rate. */
static size_t batch_size(const batch_run *u)
{
    size_t B = u->e->prm->test.batch_attempts;
    if (!B) {
        double want = SURVIVORS / u->p_surv, finish = 2.0 * (double)(u->m - u->placed) / u->p_acc;
        want = want < finish ? want : finish;
        B = want < B_MIN ? B_MIN : (want > (double)B_MAX ? B_MAX : (size_t)want);
    }
    return B;
}

/* Report progress; the stop a cancel or the wall time asks for, else
 * PK_STOP_COMPLETE. */
static pk_stop_reason progress_tick(const batch_run *u)
{
    const pk_rsa_batch_env *e = u->e;
    pk_progress *pg = e->pg;
    pg->done = e->st->placed;
    pg->fraction = (double)e->st->placed / (double)(e->st->requested ? e->st->requested : 1);
    pg->phi = *e->solid / e->box_measure;
    int cc = pk_monitor_tick(e->mon, pg, 0);
    return cc == 0 ? PK_STOP_COMPLETE : cc == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
}

/* Step 3: walk the A attempts of a batch of B draws in attempt order, accept
 * each survivor that hits neither the batch's earlier acceptances nor the
 * grid.  Sets *used (draws of the batch consumed) and *acc (accepted). */
static pk_stop_reason walk_attempts(batch_run *u, size_t S, size_t A, size_t B, size_t *used,
                                    size_t *acc)
{
    const pk_rsa_batch_env *e = u->e;
    const pk_grid *grid = e->grid;
    pk_particles *out = e->out;
    scratch *w = &u->w;
    uint8_t *map = u->map;
    const double r = u->r;
    uint64_t hmask = 63;
    while (hmask + 1 < 2 * (uint64_t)S)
        hmask = 2 * hmask + 1;
    memset(w->head, 0xff, (hmask + 1) * sizeof *w->head);
    memset(w->taken, 0, S);
    const uint64_t max_failed = e->prm->max_failed_draws;
    const size_t nword = (A + 63) / 64;
    uint64_t failed = u->failed;
    size_t placed = u->placed;
    pk_stop_reason reason = PK_STOP_COMPLETE;
    *used = B;
    *acc = 0;
    size_t a = 0;      /* next attempt of the walk */
    size_t next_d = 0; /* its first draw not yet counted */
    for (;;) {
        /* draws rejected at once or in step 2 count as failures: jump to the next survivor */
        size_t wd = a >> 6;
        uint64_t bits = wd < nword ? w->sbit[wd] & (~(uint64_t)0 << (a & 63)) : 0;
        while (!bits && ++wd < nword)
            bits = w->sbit[wd];
        a = bits ? 64 * wd + (size_t)__builtin_ctzll(bits) : A;
        size_t d = a < A ? draw_of(w, u->region, a) : B;
        if ((uint64_t)(d - next_d) >= max_failed - failed) {
            *used = next_d + (size_t)(max_failed - failed);
            failed = max_failed;
            reason = PK_STOP_MAX_FAILED_DRAWS;
            break;
        }
        failed += d - next_d;
        if (a == A)
            break;
        size_t cur = a++;
        next_d = d + 1;
        int32_t j = w->slot[cur];
        const double *x = &w->surv[3 * (size_t)j];
        const uint32_t key = w->vkey[j];
        int ok = !batch_hits(&u->C, w, map, hmask, x, key) &&
            (u->grid_empty || !pk_grid_overlaps(grid, out, x, r));
        if (!ok) {
            if (++failed >= max_failed) {
                *used = next_d;
                reason = PK_STOP_MAX_FAILED_DRAWS;
                break;
            }
            continue;
        }
        size_t idx = pk_particles_push(out, x, r, u->species[placed]);
        if (idx == (size_t)-1 || idx >= PK_RSA_CELLS_MORE) {
            *used = next_d;
            reason = PK_STOP_ERROR;
            break;
        }
        /* accepted: in the batch's hash and occupancy map until step 4 */
        w->pid[j] = (uint32_t)idx;
        failed = 0;
        placed++;
        ++*acc;
        *e->solid += u->ball;
        w->taken[j] = 1;
        uint64_t lin = pk_rsa_cells_index(key), h = hash_cell(lin, hmask);
        w->hcell[j] = lin;
        map[lin >> 3] |= (uint8_t)(1u << (lin & 7));
        w->hnext[j] = w->head[h];
        w->head[h] = j;
        if (placed == u->m) {
            *used = next_d;
            break;
        }
    }
    u->failed = failed;
    u->placed = placed;
    return reason;
}

/* Step 4: the batch's S survivors that were taken join the store (between
 * batches only: sorted order, streaming), the map is cleared, and the region
 * marks their exclusion balls and is compacted once its stale draws cost
 * about one pass over its list (STALE_PER_PASS). */
static pk_stop_reason grow_store(batch_run *u, size_t S)
{
    scratch *w = &u->w;
    pk_rsa_region *reg = &u->reg;
    const int region = u->region;
    size_t ntaken = 0;
    for (size_t j = 0; j < S; j++)
        if (w->taken[j])
            w->kept[ntaken++] = (uint32_t)j; /* (free again after step 2) */
    pk_rsa_region_spot ring[MARK_RING];
    for (size_t q = 0; region && q < ntaken && q < MARK_AHEAD; q++)
        mark_ahead(reg, ring, q, &w->surv[3 * (size_t)w->kept[q]]);
    for (size_t q = 0; q < ntaken; q++) {
        const size_t j = w->kept[q];
        if (q + INSERT_AHEAD < ntaken) {
            const uint32_t key = w->vkey[w->kept[q + INSERT_AHEAD]];
            __builtin_prefetch(&u->C.cell[pk_rsa_cells_index(key)], 1);
        }
        u->map[w->hcell[j] >> 3] = 0; /* the occupancy map is empty again */
        if (pk_rsa_cells_insert(&u->C, &w->surv[3 * j], w->pid[j]) != 0)
            return PK_STOP_ERROR;
        if (!region)
            continue;
        if (q + MARK_AHEAD < ntaken)
            mark_ahead(reg, ring, q + MARK_AHEAD, &w->surv[3 * (size_t)w->kept[q + MARK_AHEAD]]);
        pk_rsa_region_mark_at(reg, ring[q % MARK_RING]);
    }
    if (region && (u->stale_since += w->stale) * STALE_PER_PASS >= reg->nlist) {
        pk_rsa_region_compact(reg);
        u->stale_since = 0;
    }
    return PK_STOP_COMPLETE;
}

/* One batch (README.md, steps 1-4): switch to region draws once acceptance
 * is low, draw and filter, walk, rewind the stream past the draws used, grow
 * the store.  PK_STOP_COMPLETE: go on (or the run is full). */
static pk_stop_reason one_batch(batch_run *u)
{
    const pk_rsa_batch_env *e = u->e;
    pk_rng *rng = e->rng;
    const int dim = e->b->dim;
    if (!u->region && u->region_allowed && u->p_acc < REGION_SWITCH_ACC &&
        u->m - u->placed >= REGION_MIN_LEFT) {
        u->region_allowed = 0;
        u->region = region_start(&u->reg, &u->C, e->b, u->r, e->prm->delta_d, u->lo, u->span,
                                 e->out, u->first, u->m, e->mon, e->pg) == 0;
    }
    if (u->region && u->reg.nlist == 0)
        return PK_STOP_SATURATED; /* every fine voxel lies in an exclusion ball */
    size_t B = batch_size(u);
    pk_stop_reason reason = progress_tick(u);
    if (reason != PK_STOP_COMPLETE)
        return reason;
    pk_rng start = *rng;
    size_t A;
    size_t S = draw_and_filter(&u->C, e->out->x, &u->w, B, dim, u->lo, u->span, rng, u->shift,
                               u->nbucket, u->region ? &u->reg : NULL, &A);
    if (S == SIZE_MAX)
        return PK_STOP_ERROR;
    size_t used, acc;
    reason = walk_attempts(u, S, A, B, &used, &acc);
    e->st->draws += used;
    e->st->placed += acc;
    if (used < B && !u->region) { /* rewind the stream to just after the last attempt used */
        *rng = start;
        for (size_t q = 0; q < used * (size_t)dim; q++)
            pk_rng_next(rng);
    }
    /* (region draws use a varying number of outputs: the stream stays
     * where the batch left it — deterministic, not rewound) */
    u->p_surv = fmax((double)S / (double)B, 1e-6);
    u->p_acc = fmax((double)acc / (double)used, 1e-6);
    if (reason != PK_STOP_COMPLETE || u->placed == u->m)
        return reason;
    return grow_store(u, S);
}

/* The run in batches of attempts (README.md, steps 1-4). */
static pk_stop_reason run_batches(const pk_rsa_batch_env *e, double r, const int32_t *species,
                                  size_t m, const double *lo, const double *span)
{
    batch_run u;
    if (open_run(&u, e, r, species, m, lo, span) != 0)
        return PK_STOP_ERROR;
    pk_stop_reason reason = PK_STOP_COMPLETE;
    while (reason == PK_STOP_COMPLETE && u.placed < m)
        reason = one_batch(&u);
    close_run(&u);
    return reason;
}

int pk_rsa_batch_place(const pk_rsa_batch_env *e, double r, const int32_t *species, size_t m,
                       const double *lo, const double *span, pk_stop_reason *why)
{
    const uint32_t min_run = e->prm->test.batch_min_run;
    if (m < (min_run ? min_run : PK_RSA_BATCH_MIN_RUN) ||
        !usable(e->b, r, e->prm->delta_d, span, m))
        return 0;
    *why =
        e->enter && e->enter(e->ctx) != 0 ? PK_STOP_ERROR : run_batches(e, r, species, m, lo, span);
    return 1;
}
