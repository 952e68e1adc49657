#include "rsa_batch.h"
#include "rng.h"

#include <stdlib.h>
#include <string.h>

#include "rsa_cells.h"

/* Batch size: enough attempts that the cell-ordered tests share cache lines
 * (B_MIN), few enough survivors that step 3's hash stays in cache
 * (SURVIVORS), bounded memory (B_MAX attempts ≈ 60 MB of scratch). */
#define B_MIN 4096
#define B_MAX ((size_t)1 << 20)
#define SURVIVORS 32768.0
/* Counting sort of attempts by cell: at most this many buckets (contiguous
 * ranges of cell indices), so the scatter writes few streams. */
#define MAX_BUCKETS 4096
/* The store may not be much larger than the run needs (a few fine grains in
 * a huge box keep the per-grain path). */
#define CELLS_PER_GRAIN 64
#define CELLS_FREE 65536

int pk_rsa_batch_usable(const pk_box *b, double r, double gap, const double *lo,
                        const double *span, size_t m)
{
    uint64_t nc = pk_rsa_cells_count(b, r, gap, span);
    return nc > 0 && nc <= (uint64_t)CELLS_PER_GRAIN * m + CELLS_FREE;
}

typedef struct scratch {
    size_t cap;
    double *pos;        /* [cap][3] attempts in attempt order */
    uint32_t *key;      /* bucket of each attempt */
    double *spos;       /* [cap][3] attempts in bucket order */
    uint32_t *sidx;     /* attempt index of each sorted entry */
    uint32_t *skey;     /* its cell key */
    uint32_t *kept;     /* sorted positions of the survivors of step 2 */
    uint64_t *sbit;     /* bit a: attempt a survived step 2 */
    int32_t *slot;      /* survivor number of attempt a (set where sbit is) */
    double *surv;       /* [cap][3] survivors in sorted order */
    uint8_t *taken;     /* survivor accepted in step 3 */
    uint32_t *count;    /* [MAX_BUCKETS + 1] */
    /* step 3: hash of the batch's accepted survivors by cell */
    int32_t *head;      /* [power of two >= 2 cap] */
    int32_t *hnext;     /* per survivor */
    uint64_t *hcell;    /* per survivor: its cell */
} scratch;

static void scratch_free(scratch *w)
{
    free(w->pos);
    free(w->key);
    free(w->spos);
    free(w->sidx);
    free(w->skey);
    free(w->kept);
    free(w->sbit);
    free(w->slot);
    free(w->surv);
    free(w->taken);
    free(w->count);
    free(w->head);
    free(w->hnext);
    free(w->hcell);
    memset(w, 0, sizeof *w);
}

/* realloc that keeps the old block and sets *fail when it cannot grow. */
static void *grow(void *p, size_t bytes, int *fail)
{
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q)
        *fail = 1;
    return q ? q : p;
}

/* Room for batches of B attempts (grows only; -1 when out of memory). */
static int scratch_reserve(scratch *w, size_t B)
{
    if (B <= w->cap)
        return 0;
    uint64_t hb = 64;
    while (hb < 2 * (uint64_t)B)
        hb <<= 1;
    int fail = 0;
    w->pos = grow(w->pos, 3 * B * sizeof *w->pos, &fail);
    w->key = grow(w->key, B * sizeof *w->key, &fail);
    w->spos = grow(w->spos, 3 * B * sizeof *w->spos, &fail);
    w->sidx = grow(w->sidx, B * sizeof *w->sidx, &fail);
    w->skey = grow(w->skey, B * sizeof *w->skey, &fail);
    w->kept = grow(w->kept, B * sizeof *w->kept, &fail);
    w->sbit = grow(w->sbit, (B / 64 + 1) * sizeof *w->sbit, &fail);
    w->slot = grow(w->slot, B * sizeof *w->slot, &fail);
    w->surv = grow(w->surv, 3 * B * sizeof *w->surv, &fail);
    w->taken = grow(w->taken, B, &fail);
    w->count = grow(w->count, (MAX_BUCKETS + 1) * sizeof *w->count, &fail);
    w->head = grow(w->head, hb * sizeof *w->head, &fail);
    w->hnext = grow(w->hnext, B * sizeof *w->hnext, &fail);
    w->hcell = grow(w->hcell, B * sizeof *w->hcell, &fail);
    if (fail)
        return -1;
    w->cap = B;
    return 0;
}

static inline uint64_t hash_cell(uint64_t lin, uint64_t mask)
{
    return (lin * 0x9E3779B97F4A7C15ull) >> 20 & mask;
}

/* Step 3's test: is survivor x (key: pk_rsa_cells_key) within contact of a
 * survivor accepted earlier in this batch?  Off the seams the neighbours are
 * the fixed offsets of the filter; ghost cells never match a stored cell. */
static int batch_hits(const pk_rsa_cells *C, const scratch *w, uint64_t hmask, const double *x,
                      uint32_t key)
{
    uint64_t nb[27];
    int m;
    if (C->cell[pk_rsa_cells_index(key)].seam) {
        m = pk_rsa_cells_around(C, x, nb);
    } else {
        const int64_t *off = C->off[pk_rsa_cells_octant(key)];
        nb[0] = pk_rsa_cells_index(key);
        for (int q = 0; q < C->noff; q++)
            nb[q + 1] = (uint64_t)((int64_t)nb[0] + off[q]);
        m = C->noff + 1;
    }
    for (int q = 0; q < m; q++)
        for (int32_t j = w->head[hash_cell(nb[q], hmask)]; j >= 0; j = w->hnext[j])
            if (w->hcell[j] == nb[q] && pk_rsa_cells_close(C, &w->surv[3 * (size_t)j], x))
                return 1;
    return 0;
}

/* Steps 1–2 for B attempts: draw, sort by cell bucket, filter against the
 * store.  Returns the number of survivors. */
static size_t draw_and_filter(const pk_rsa_cells *C, scratch *w, size_t B, int dim,
                              const double *lo, const double *span, pk_rng *rng, int shift,
                              uint32_t nbucket)
{
    memset(w->count, 0, (nbucket + 1) * sizeof *w->count);
    const double lo0 = lo[0], lo1 = lo[1], lo2 = lo[2], sp0 = span[0], sp1 = span[1];
    const double sp2 = dim == 3 ? span[2] : 0;
    /* local copies: the stores below cannot alias them, so the generator state
     * and the store's geometry stay in registers */
    pk_rng g = *rng;
    const pk_rsa_cells K = *C;
    double *restrict pos = w->pos;
    uint32_t *restrict keys = w->key, *restrict count = w->count;
    for (size_t a = 0; a < B; a++) {
        /* rsa.c's plain draw: x[k] = lo[k] + span[k]·u, k = 0, 1 (, 2), z = 0 in 2D */
        double x[3];
        x[0] = lo0 + sp0 * pk_rng_uniform(&g);
        x[1] = lo1 + sp1 * pk_rng_uniform(&g);
        x[2] = dim == 3 ? lo2 + sp2 * pk_rng_uniform(&g) : 0;
        memcpy(&pos[3 * a], x, sizeof x);
        uint32_t key = pk_rsa_cells_key(&K, x);
        keys[a] = key;
        count[(pk_rsa_cells_index(key) >> shift) + 1]++;
    }
    *rng = g;
    for (uint32_t k = 0; k < nbucket; k++)
        w->count[k + 1] += w->count[k];
    for (size_t a = 0; a < B; a++) {
        uint32_t key = w->key[a];
        uint32_t t = w->count[pk_rsa_cells_index(key) >> shift]++;
        memcpy(&w->spos[3 * (size_t)t], &w->pos[3 * a], 3 * sizeof(double));
        w->sidx[t] = (uint32_t)a;
        w->skey[t] = key;
    }
    size_t S = pk_rsa_cells_filter(C, w->spos, w->skey, B, w->kept);
    memset(w->sbit, 0, (B / 64 + 1) * sizeof *w->sbit);
    for (size_t j = 0; j < S; j++) {
        uint32_t t = w->kept[j], a = w->sidx[t];
        memcpy(&w->surv[3 * j], &w->spos[3 * (size_t)t], 3 * sizeof(double));
        w->slot[a] = (int32_t)j;
        w->sbit[a >> 6] |= (uint64_t)1 << (a & 63);
    }
    return S;
}

pk_stop_reason pk_rsa_batch_run(const pk_box *b, double r, const int32_t *species, size_t m,
                                const double *lo, const double *span, const pk_rsa_params *prm,
                                const pk_grid *grid, pk_rng *rng, pk_monitor *mon,
                                pk_progress *pg, double box_measure, double *solid,
                                pk_particles *out, pk_rsa_stats *st)
{
    pk_rsa_cells C;
    if (pk_rsa_cells_init(&C, b, r, prm->delta_d, lo, span) != 0)
        return PK_STOP_ERROR;
    scratch w;
    memset(&w, 0, sizeof w);
    int shift = 0;
    while (((C.ncell - 1) >> shift) >= MAX_BUCKETS)
        shift++;
    const uint32_t nbucket = (uint32_t)((C.ncell - 1) >> shift) + 1;
    int grid_empty = 1;
    for (int l = 0; l < grid->nlevel; l++)
        grid_empty &= grid->lv[l].count == 0;
    const double ball = pk_ball_measure(b->dim, r);

    pk_stop_reason reason = PK_STOP_COMPLETE;
    size_t placed = 0;
    uint64_t failed = 0;
    double p_surv = 1, p_acc = 1; /* running estimates from the last batch */
    while (placed < m) {
        size_t B = prm->batch_attempts;
        if (!B) {
            double want = SURVIVORS / p_surv, finish = 2.0 * (double)(m - placed) / p_acc;
            want = want < finish ? want : finish;
            B = want < B_MIN ? B_MIN : (want > (double)B_MAX ? B_MAX : (size_t)want);
        }
        pg->done = st->placed;
        pg->fraction = (double)st->placed / (double)(st->requested ? st->requested : 1);
        pg->phi = *solid / box_measure;
        int c = pk_monitor_tick(mon, pg, 0);
        if (c) {
            reason = c == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
            break;
        }
        if (scratch_reserve(&w, B) != 0) {
            reason = PK_STOP_ERROR;
            break;
        }
        pk_rng start = *rng;
        size_t S = draw_and_filter(&C, &w, B, b->dim, lo, span, rng, shift, nbucket);

        /* step 3: attempt order */
        uint64_t hmask = 63;
        while (hmask + 1 < 2 * (uint64_t)S)
            hmask = 2 * hmask + 1;
        memset(w.head, 0xff, (hmask + 1) * sizeof *w.head);
        memset(w.taken, 0, S);
        size_t used = B, acc = 0;
        const uint64_t max_failed = prm->max_failed_draws;
        size_t a = 0; /* next attempt of the walk */
        for (;;) {
            /* attempts rejected in step 2 count as failures: jump to the next survivor */
            size_t a0 = a, wd = a >> 6;
            uint64_t bits = wd < (B + 63) / 64 ? w.sbit[wd] & (~(uint64_t)0 << (a & 63)) : 0;
            while (!bits && ++wd < (B + 63) / 64)
                bits = w.sbit[wd];
            a = bits ? 64 * wd + (size_t)__builtin_ctzll(bits) : B;
            if ((uint64_t)(a - a0) >= max_failed - failed) {
                used = a0 + (size_t)(max_failed - failed);
                failed = max_failed;
                reason = PK_STOP_MAX_FAILED_DRAWS;
                break;
            }
            failed += a - a0;
            if (a == B)
                break;
            size_t cur = a++;
            int32_t j = w.slot[cur];
            const double *x = &w.surv[3 * (size_t)j];
            uint32_t key = pk_rsa_cells_key(&C, x);
            int ok = !batch_hits(&C, &w, hmask, x, key) &&
                     (grid_empty || !pk_grid_overlaps(grid, out, x, r));
            if (!ok) {
                if (++failed >= max_failed) {
                    used = cur + 1;
                    reason = PK_STOP_MAX_FAILED_DRAWS;
                    break;
                }
                continue;
            }
            if (pk_particles_push(out, x, r, species[placed]) == (size_t)-1) {
                used = cur + 1;
                reason = PK_STOP_ERROR;
                break;
            }
            failed = 0;
            placed++;
            acc++;
            *solid += ball;
            w.taken[j] = 1;
            uint64_t lin = pk_rsa_cells_index(key), h = hash_cell(lin, hmask);
            w.hcell[j] = lin;
            w.hnext[j] = w.head[h];
            w.head[h] = j;
            if (placed == m) {
                used = cur + 1;
                break;
            }
        }
        st->draws += used;
        st->placed += acc;
        if (used < B) { /* rewind the stream to just after the last attempt used */
            *rng = start;
            for (size_t q = 0; q < used * (size_t)b->dim; q++)
                pk_rng_next(rng);
        }
        p_surv = fmax((double)S / (double)B, 1e-6);
        p_acc = fmax((double)acc / (double)used, 1e-6);
        if (reason != PK_STOP_COMPLETE || placed == m)
            break;
        /* step 4: the store grows between batches only (sorted order: streaming) */
        for (size_t j = 0; j < S; j++)
            if (w.taken[j] && pk_rsa_cells_insert(&C, &w.surv[3 * j]) != 0) {
                reason = PK_STOP_ERROR;
                break;
            }
        if (reason != PK_STOP_COMPLETE)
            break;
    }
    scratch_free(&w);
    pk_rsa_cells_free(&C);
    return reason;
}
