/* edmd_queue.c — the event queue: each grain's one pending event in a
 * calendar of time slots (Paul 2007, J. Comput. Phys. 221, 615: O(1) per
 * event).  Contract: the edmd_queue_* declarations in core/edmd/edmd_state.h.
 *
 * slot(t) = floor((t − T0)/w), with w sized at each (re)build so a slot
 * holds about PER_SLOT events.  The current slot's events sit in a small
 * 4-ary heap; the events of the next slots, up to lap_end, in unsorted
 * doubly linked bucket lists (bucket = slot mod nb, one list per slot in the
 * window); later ones in an overflow list, sorted into the buckets when a lap
 * of nb slots starts.  Exact order: slot() is monotone in t (a subtraction
 * and a product by a positive constant, rounded, then floor), so a grain in
 * a later slot never has an earlier time than one in the heap.  Ties between
 * equal times come out in an order of their own (each order is exact).
 *
 * Why: a heap of all N events makes every event wait on ~log4 N cache lines
 * and a chain of compares (a quarter of the CPU time of mono 3D N = 10^4 to
 * jamming); here an event costs a small heap's pop and a list insert
 * (docs/perf/edmd.md). */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "edmd_state.h"

enum { ARITY = 4 };
enum { Q_HEAP = -1, Q_OVER = -2 };
#define SLOT_INF ((int64_t)1 << 62) /* infinite (or absurd) times */
/* Events per slot aimed at: fewer empty slots to skip against a larger heap
 * per slot (2 or 8: within 3 %, docs/perf/edmd.md). */
#define PER_SLOT 4.0
#define SAMPLE_MAX 1024

static uint32_t nb_cap(size_t n)
{
    uint32_t c = 64;
    while (c < 4 * n && c < (1u << 26))
        c <<= 1;
    return c;
}

int edmd_queue_alloc(edmd_state *s, size_t n)
{
    edmd_queue *q = &s->q;
    memset(q, 0, sizeof *q);
    const uint32_t cap = nb_cap(n);
    q->head = edmd_big_calloc(cap + 1, sizeof *q->head);
    q->occ = malloc(cap / 64 * sizeof *q->occ);
    q->node = edmd_big_calloc(n, sizeof *q->node);
    q->sample = malloc(SAMPLE_MAX * sizeof *q->sample);
    /* heap node k at heap_mem[k + 3]: the 4 children 4k+1..4k+4 of a node
     * share one 64-byte line (16-byte nodes); 3 sentinels follow the last */
    q->heap_mem = aligned_alloc(64, ((n + 3 + 3 + 3) / 4 + 1) * 64);
    q->heap = q->heap_mem ? q->heap_mem + 3 : NULL;
    if (!q->head || !q->occ || !q->node || !q->sample || !q->heap)
        return -1;
    return 0;
}

void edmd_queue_free(edmd_state *s)
{
    edmd_queue *q = &s->q;
    free(q->head);
    free(q->occ);
    free(q->node);
    free(q->sample);
    free(q->heap_mem);
    memset(q, 0, sizeof *q);
}

/* --- the current slot's heap --- */

static inline void hplace(edmd_queue *q, size_t k, edmd_hnode e)
{
    q->heap[k] = e;
    q->node[e.i].hpos = (int32_t)k;
}

/* Nodes hn .. hn + 2 are sentinels at +inf: the last parent's child group is
 * always full, no bound per child. */
static inline void sentinels(edmd_queue *q)
{
    for (size_t k = q->hn; k < q->hn + ARITY - 1; k++)
        q->heap[k] = (edmd_hnode){INFINITY, -1};
}

static void sift_up(edmd_queue *q, size_t k)
{
    edmd_hnode e = q->heap[k];
    while (k > 0) {
        size_t p = (k - 1) / ARITY;
        if (!(e.t < q->heap[p].t))
            break;
        hplace(q, k, q->heap[p]);
        k = p;
    }
    hplace(q, k, e);
}

/* The child is picked by index arithmetic, without branches (a coin toss
 * for the predictor); ties go to the lower node. */
static void sift_down(edmd_queue *q, size_t k)
{
    edmd_hnode *h = q->heap;
    const edmd_hnode e = h[k];
    const size_t n = q->hn;
    for (size_t c = ARITY * k + 1; c < n; c = ARITY * k + 1) {
        const edmd_hnode *ch = &h[c];
        const size_t a = ch[1].t < ch[0].t, b = 2 + (ch[3].t < ch[2].t);
        const size_t m = a + ((b - a) & (0 - (size_t)(ch[b].t < ch[a].t)));
        if (!(ch[m].t < e.t))
            break;
        hplace(q, k, ch[m]);
        k = c + m;
    }
    hplace(q, k, e);
}

static void heap_push(edmd_queue *q, size_t i, double t)
{
    const size_t k = q->hn++;
    sentinels(q);
    q->heap[k] = (edmd_hnode){t, (int32_t)i};
    q->node[i].hpos = (int32_t)k;
    sift_up(q, k);
}

static void heap_remove(edmd_queue *q, size_t k)
{
    const double old = q->heap[k].t;
    const edmd_hnode last = q->heap[--q->hn];
    sentinels(q);
    if (k == q->hn)
        return;
    q->heap[k] = last;
    q->node[last.i].hpos = (int32_t)k;
    if (last.t < old)
        sift_up(q, k);
    else
        sift_down(q, k);
}

/* --- slots and lists --- */

static inline int64_t slot_of(const edmd_queue *q, double t)
{
    const double x = (t - q->T0) * q->inv_w;
    if (!(x < 0x1p61))
        return SLOT_INF; /* +inf (or NaN) */
    if (!(x > -0x1p61))
        return -SLOT_INF;
    int64_t k = (int64_t)x; /* floor: monotone in x */
    return (double)k > x ? k - 1 : k;
}

/* List b (a bucket, or nb: the overflow). */
static inline void list_push(edmd_queue *q, uint32_t b, size_t i)
{
    const int32_t h = q->head[b];
    q->node[i].nxt = h;
    q->node[i].prv = -1;
    if (h >= 0)
        q->node[h].prv = (int32_t)i;
    q->head[b] = (int32_t)i;
    if (b < q->nb)
        q->occ[b >> 6] |= (uint64_t)1 << (b & 63);
}

static inline void list_unlink(edmd_queue *q, uint32_t b, size_t i)
{
    const int32_t nx = q->node[i].nxt, pv = q->node[i].prv;
    assert(pv < 0 ? q->head[b] == (int32_t)i : q->node[pv].nxt == (int32_t)i);
    assert(nx < 0 || q->node[nx].prv == (int32_t)i);
    if (pv >= 0)
        q->node[pv].nxt = nx;
    else
        q->head[b] = nx;
    if (nx >= 0)
        q->node[nx].prv = pv;
    if (b < q->nb && q->head[b] < 0)
        q->occ[b >> 6] &= ~((uint64_t)1 << (b & 63));
}

/* File grain i by its slot sl (>= cur): heap, bucket or overflow. */
static void file(edmd_state *s, size_t i, int64_t sl)
{
    edmd_queue *q = &s->q;
    if (sl <= q->cur) {
        q->node[i].where = Q_HEAP;
        heap_push(q, i, s->ev[i].t);
    } else if (sl < q->lap_end) {
        const uint32_t b = (uint32_t)sl & q->mask;
        q->node[i].where = (int32_t)b;
        list_push(q, b, i);
    } else {
        q->node[i].where = Q_OVER;
        list_push(q, q->nb, i);
    }
}

static void unfile(edmd_queue *q, size_t i)
{
    const int32_t w = q->node[i].where;
    if (w == Q_HEAP)
        heap_remove(q, (size_t)q->node[i].hpos);
    else
        list_unlink(q, w == Q_OVER ? q->nb : (uint32_t)w, i);
}

/* The first slot in [from, to) whose bucket holds grains, or -1 (to − from
 * <= nb, nb a multiple of 64). */
static int64_t next_occupied(const edmd_queue *q, int64_t from, int64_t to)
{
    int64_t left = to - from, sl = from;
    uint32_t b = (uint32_t)from & q->mask;
    while (left > 0) {
        const uint64_t w = q->occ[b >> 6] >> (b & 63);
        if (w) {
            const int z = __builtin_ctzll(w);
            return z < left ? sl + z : -1;
        }
        const uint32_t step = 64 - (b & 63);
        sl += step;
        left -= step;
        b = (b + step) & q->mask;
    }
    return -1;
}

/* A new lap from slot `start`: the overflow's grains of slots below
 * start + nb go to the heap (slot start) or their buckets. */
static void new_lap(edmd_state *s, int64_t start)
{
    edmd_queue *q = &s->q;
    q->cur = start;
    q->lap_end = start + q->nb;
    for (int32_t i = q->head[q->nb], nx; i >= 0; i = nx) {
        nx = q->node[i].nxt; /* (file() puts i in the heap or a bucket, not back here) */
        const int64_t sl = slot_of(q, s->ev[i].t); /* as when it was filed */
        if (sl < q->lap_end) {
            list_unlink(q, q->nb, (size_t)i);
            file(s, (size_t)i, sl);
        }
    }
}

/* The heap is empty: move on to the next slot that holds grains. */
static void advance(edmd_state *s)
{
    edmd_queue *q = &s->q;
    const int64_t sl = next_occupied(q, q->cur + 1, q->lap_end);
    if (sl >= 0) {
        q->cur = sl;
        const uint32_t b = (uint32_t)sl & q->mask;
        int32_t i = q->head[b];
        q->head[b] = -1;
        q->occ[b >> 6] &= ~((uint64_t)1 << (b & 63));
        while (i >= 0) {
            const int32_t nx = q->node[i].nxt;
            q->node[i].where = Q_HEAP;
            heap_push(q, (size_t)i, s->ev[i].t);
            i = nx;
        }
        return;
    }
    new_lap(s, q->lap_end); /* the buckets are empty: all grains are in the overflow */
    if (q->hn > 0 || next_occupied(q, q->cur + 1, q->lap_end) >= 0)
        return;
    int64_t lo = SLOT_INF; /* nothing in this lap either: jump to the earliest */
    for (int32_t i = q->head[q->nb]; i >= 0; i = q->node[i].nxt) {
        const int64_t si = slot_of(q, s->ev[i].t);
        lo = si < lo ? si : lo;
    }
    new_lap(s, lo);
}

size_t edmd_queue_top(edmd_state *s)
{
    while (s->q.hn == 0)
        advance(s);
    return (size_t)s->q.heap[0].i;
}

/* The grain most likely next after the top (the least of the root's
 * children: the next event unless this one's new predictions come first),
 * or -1 when the current slot holds no other event. */
int32_t edmd_queue_runner_up(const edmd_state *s)
{
    const edmd_queue *q = &s->q;
    if (q->hn < 2)
        return -1;
    const edmd_hnode *ch = &q->heap[1]; /* nodes hn .. hn + 2 are +inf sentinels */
    size_t m = 0;
    const size_t last = q->hn - 1 < ARITY ? q->hn - 1 : ARITY;
    for (size_t c = 1; c < last; c++)
        m = ch[c].t < ch[m].t ? c : m;
    return ch[m].i;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Slot width and bucket count from the pending events: the rate of events
 * just ahead (the spread of the earliest 1/16 of a sample) gives w for
 * PER_SLOT events a slot; the buckets reach the sample's 90th percentile. */
static void size_slots(edmd_state *s)
{
    edmd_queue *q = &s->q;
    const size_t n = s->n, stride = n > SAMPLE_MAX ? n / SAMPLE_MAX : 1;
    size_t len = 0;
    for (size_t i = 0; i < n && len < SAMPLE_MAX; i += stride) {
        const double d = s->ev[i].t - s->t;
        if (d < INFINITY)
            q->sample[len++] = d > 0 ? d : 0;
    }
    double w = 1, reach = 64;
    if (len > 0) {
        qsort(q->sample, len, sizeof *q->sample, cmp_double);
        size_t k = len / 16;
        while (k + 1 < len && !(q->sample[k] > 0))
            k++;
        const double dk = q->sample[k];
        if (dk > 0) {
            /* rate R ≈ (k + 1)·(n/len) events in dk */
            w = PER_SLOT * dk * (double)len / ((double)(k + 1) * (double)n);
            reach = q->sample[len * 9 / 10] / w;
        }
    }
    q->T0 = s->t;
    q->inv_w = 1 / w;
    const uint32_t cap = nb_cap(n);
    uint32_t nb = 64;
    while (nb < cap && (double)nb < reach)
        nb <<= 1;
    q->nb = nb;
    q->mask = nb - 1;
}

void edmd_queue_init(edmd_state *s)
{
    edmd_queue *q = &s->q;
    size_slots(s);
    q->hn = 0;
    sentinels(q);
    for (uint32_t b = 0; b <= q->nb; b++)
        q->head[b] = -1;
    memset(q->occ, 0, q->nb / 64 * sizeof *q->occ);
    q->cur = 0; /* slot_of(s->t) */
    q->lap_end = q->nb;
    for (size_t i = 0; i < s->n; i++) {
        int64_t sl = slot_of(q, s->ev[i].t);
        file(s, i, sl > 0 ? sl : 0);
    }
}

void edmd_queue_update(edmd_state *s, size_t i)
{
    edmd_queue *q = &s->q;
    const double t = s->ev[i].t;
    int64_t sl = slot_of(q, t);
    if (sl < q->cur)
        sl = q->cur;                                  /* (never: events lie ahead of the clock) */
    if (q->node[i].where == Q_HEAP && sl == q->cur) { /* re-keyed in the heap */
        const size_t k = (size_t)q->node[i].hpos;
        const double old = q->heap[k].t;
        q->heap[k].t = t;
        if (t < old)
            sift_up(q, k);
        else
            sift_down(q, k);
        return;
    }
    unfile(q, i);
    file(s, i, sl);
}

void edmd_queue_shift(edmd_state *s, double dt)
{
    for (size_t i = 0; i < s->n; i++) {
        s->ev[i].t -= dt;
        s->ev[i].t2 -= dt;
    }
    edmd_queue_init(s); /* slots about the shifted clock s->t */
}
