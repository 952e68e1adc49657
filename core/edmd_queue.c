/* edmd_queue.c — the event queue: a binary heap holding each particle's one
 * pending event (keyed by ev_t), with positions for O(log N) re-keying. */
#include <stdlib.h>

#include "edmd_state.h"

static inline int before(const edmd_state *s, int32_t a, int32_t b)
{
    return s->ev_t[a] < s->ev_t[b];
}

static void sift_up(edmd_state *s, size_t k)
{
    int32_t e = s->heap[k];
    while (k > 0) {
        size_t p = (k - 1) / 2;
        if (!before(s, e, s->heap[p]))
            break;
        s->heap[k] = s->heap[p];
        s->hpos[s->heap[k]] = (int32_t)k;
        k = p;
    }
    s->heap[k] = e;
    s->hpos[e] = (int32_t)k;
}

static void sift_down(edmd_state *s, size_t k)
{
    int32_t e = s->heap[k];
    for (;;) {
        size_t c = 2 * k + 1;
        if (c >= s->hn)
            break;
        if (c + 1 < s->hn && before(s, s->heap[c + 1], s->heap[c]))
            c++;
        if (!before(s, s->heap[c], e))
            break;
        s->heap[k] = s->heap[c];
        s->hpos[s->heap[k]] = (int32_t)k;
        k = c;
    }
    s->heap[k] = e;
    s->hpos[e] = (int32_t)k;
}

int edmd_queue_init(edmd_state *s)
{
    s->hn = s->n;
    for (size_t i = 0; i < s->n; i++) {
        s->heap[i] = (int32_t)i;
        s->hpos[i] = (int32_t)i;
    }
    for (size_t k = s->hn / 2; k-- > 0;)
        sift_down(s, k);
    return 0;
}

void edmd_queue_update(edmd_state *s, size_t i)
{
    size_t k = (size_t)s->hpos[i];
    if (k > 0 && before(s, (int32_t)i, s->heap[(k - 1) / 2]))
        sift_up(s, k);
    else
        sift_down(s, k);
}

void edmd_queue_shift(edmd_state *s, double dt)
{
    /* a uniform shift keeps the heap order */
    for (size_t i = 0; i < s->n; i++)
        s->ev_t[i] -= dt;
}
