/* test_edmd_queue.c — the EDMD event queue (core/edmd/edmd_queue.c, a calendar
 * of time slots): driven as the engine drives it, against a brute-force
 * minimum.  Each step takes the top grain i, checks that its time is the
 * smallest pending one (ties: any grain at that time) and never earlier
 * than the previous top, gives it a new time ahead of the clock and
 * re-files it, and re-times a random partner j (earlier or later than its
 * old time, never behind the clock) — with event spacings spread over six
 * decades (the slot width is sized from a sample: far events go to the
 * overflow and return lap by lap), exact ties (a collision's two grains,
 * events "now"), grains with no event (+inf) and a clock re-based every
 * 4N steps (edmd_queue_shift, which rebuilds the slots).  Exact
 * comparisons: the queue must order times exactly, not to a tolerance. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/edmd/edmd_state.h"
#include "core/base/rng.h"

/* A time ahead of now: log-uniform spacing over six decades, sometimes 0
 * (an event now), sometimes +inf (no event). */
static double ahead(pk_rng *g, double now, double scale)
{
    const double u = pk_rng_uniform(g);
    if (u < 0.02)
        return now;
    if (u < 0.03)
        return INFINITY;
    return now + scale * pow(10.0, 6 * pk_rng_uniform(g) - 3);
}

static size_t brute_min(const edmd_state *s, double *tmin)
{
    size_t best = 0;
    for (size_t i = 1; i < s->n; i++)
        if (s->ev[i].t < s->ev[best].t)
            best = i;
    *tmin = s->ev[best].t;
    return best;
}

static void run(size_t n, uint64_t seed, int steps)
{
    edmd_state S;
    memset(&S, 0, sizeof S);
    edmd_state *s = &S;
    s->n = n;
    s->ev = calloc(n, sizeof *s->ev);
    CHECK(edmd_queue_alloc(s, n) == 0);
    pk_rng g;
    pk_rng_seed(&g, seed, 9);
    for (size_t i = 0; i < n; i++)
        s->ev[i] = (edmd_event){ahead(&g, 0, 1), INFINITY, -1, -1, 0, 0};
    edmd_queue_init(s);
    double last = 0;
    int bad_order = 0, bad_min = 0;
    for (int step = 1; step <= steps; step++) {
        const size_t i = edmd_queue_top(s);
        double tmin;
        brute_min(s, &tmin);
        bad_min += s->ev[i].t != tmin;
        bad_order += s->ev[i].t < last;
        if (!(s->ev[i].t < INFINITY)) { /* nobody has an event: give everyone one */
            for (size_t k = 0; k < n; k++)
                s->ev[k].t = ahead(&g, s->t, 1);
            edmd_queue_init(s);
            continue;
        }
        last = s->t = s->ev[i].t;
        /* a collision: i and a partner get new times, sometimes equal */
        const size_t j = (size_t)(pk_rng_next(&g) % n);
        const double scale = pk_rng_uniform(&g) < 0.5 ? 1 : 1e-3;
        s->ev[i].t = ahead(&g, s->t, scale);
        edmd_queue_update(s, i);
        if (j != i) {
            s->ev[j].t = pk_rng_uniform(&g) < 0.2 ? s->ev[i].t : ahead(&g, s->t, scale);
            edmd_queue_update(s, j);
        }
        if (step % (int)(4 * n) == 0) { /* re-base the clock, as edmd.c's rebase */
            const double T = s->t;
            s->t = 0;
            last -= T;
            edmd_queue_shift(s, T);
        }
    }
    CHECK_MSG(bad_min == 0, "n=%zu: %d tops were not the earliest event", n, bad_min);
    CHECK_MSG(bad_order == 0, "n=%zu: %d tops went back in time", n, bad_order);
    edmd_queue_free(s);
    free(s->ev);
}

static void test_top_is_the_earliest_event(void)
{
    run(1, 1, 200);
    run(7, 2, 5000);
    run(300, 3, 60000);
    run(5000, 4, 60000);
}

int main(void)
{
    RUN(test_top_is_the_earliest_event);
    return check_summary();
}
