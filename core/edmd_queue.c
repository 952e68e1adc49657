/* edmd_queue.c — the event queue: a 4-ary heap holding each particle's one
 * pending event.  Each node carries its key (the event time) inline, so a
 * sift compares neighbouring memory instead of chasing ev[].t of random
 * particles; 4 children per node halve the depth (fewer cache lines per
 * re-key).  hpos[i] is the node of particle i, for O(log N) re-keying. */
#include <math.h>
#include <stdlib.h>

#include "edmd_state.h"

enum { ARITY = 4 };

static inline void place(edmd_state *s, size_t k, edmd_hnode e)
{
    s->heap[k] = e;
    s->hpos[e.i] = (int32_t)k;
}

static void sift_up(edmd_state *s, size_t k)
{
    edmd_hnode e = s->heap[k];
    while (k > 0) {
        size_t p = (k - 1) / ARITY;
        if (!(e.t < s->heap[p].t))
            break;
        place(s, k, s->heap[p]);
        k = p;
    }
    place(s, k, e);
}

/* The heap is followed by ARITY − 1 nodes at +inf (edmd_queue_init), so the
 * last parent's child group is always full: no bound per child.  The child
 * is picked by index arithmetic, without branches: gcc made one branch of
 * the choice between the two pairs, taken at random.  Same choice, same
 * heap, same events; mono 3D N = 10^4, first 3M events (callgrind
 * --branch-sim): sift_down mispredictions 14.6M → 3.9M for +8.5 % of its
 * instructions (+79M against −10.7M mispredictions of ~15 cycles).  Round
 * 7: the four keys loaded once and the pair minima kept (no reload of
 * ch[a], ch[b], ch[m]): same choice, Fuller-like 1–16 N = 10^4 to jamming
 * 26.4023G → 26.4023G instructions; dropped. */
static void sift_down(edmd_state *s, size_t k)
{
    edmd_hnode *h = s->heap;
    int32_t *hpos = s->hpos;
    const edmd_hnode e = h[k];
    const size_t n = s->hn;
    for (size_t c = ARITY * k + 1; c < n; c = ARITY * k + 1) {
        const edmd_hnode *ch = &h[c];
        const size_t a = ch[1].t < ch[0].t, b = 2 + (ch[3].t < ch[2].t);
        const size_t m = a + ((b - a) & (0 - (size_t)(ch[b].t < ch[a].t)));
        if (!(ch[m].t < e.t))
            break;
        const edmd_hnode up = ch[m];
        h[k] = up;
        hpos[up.i] = (int32_t)k;
        k = c + m;
    }
    h[k] = e;
    hpos[e.i] = (int32_t)k;
}

int edmd_queue_init(edmd_state *s)
{
    s->hn = s->n;
    for (size_t i = 0; i < s->n; i++)
        place(s, i, (edmd_hnode){s->ev[i].t, (int32_t)i});
    for (size_t q = 0; q + 1 < ARITY; q++) /* sentinels, never moved */
        s->heap[s->n + q] = (edmd_hnode){INFINITY, -1};
    for (size_t k = s->hn / ARITY + 1; k-- > 0;)
        if (k < s->hn)
            sift_down(s, k);
    return 0;
}

void edmd_queue_update(edmd_state *s, size_t i)
{
    size_t k = (size_t)s->hpos[i];
    double t = s->ev[i].t, old = s->heap[k].t;
    s->heap[k].t = t;
    if (t < old)
        sift_up(s, k);
    else
        sift_down(s, k);
}

void edmd_queue_shift(edmd_state *s, double dt)
{
    /* a uniform shift keeps the heap order */
    for (size_t i = 0; i < s->n; i++) {
        s->ev[i].t -= dt;
        s->ev[i].t2 -= dt;
        s->heap[i].t -= dt;
    }
}
