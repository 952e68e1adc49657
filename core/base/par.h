/* par.h — a small persistent thread pool (C17 <threads.h> + <stdatomic.h>)
 * for the short parallel sections of the relaxations (a DR/FIRE iteration
 * is ~0.1–0.3 ms, so a section is tens of µs: the workers must be waiting
 * when it comes, not being woken).
 *
 * pk_par_run(p, fn, ctx) runs fn(ctx, t, nt) for t = 0 .. nt−1, t = 0 on
 * the calling thread, the others on whichever thread claims them first (a
 * part no worker has taken yet when the caller is done runs on the caller:
 * a worker asleep or descheduled never holds the caller up), and returns
 * when all have returned; what the calls wrote is then visible to the
 * caller (release/acquire).  fn must give the same results for any nt and
 * whichever thread runs a part (the callers' contract: results never
 * depend on the deployment), because a NULL pool, a pool without threads
 * support (__STDC_NO_THREADS__) and a pool already running a job (a nested
 * or a concurrent pk_par_run) all run fn(ctx, 0, 1) on the caller.
 *
 * Between jobs a worker spins on the job counter for PK_PAR_SPIN_NS (with a
 * CPU pause per poll and a thrd_yield every 50 µs, so a process that needs
 * the core gets it), then blocks on a condition variable: an idle pool burns
 * no core. */
#ifndef PK_PAR_H
#define PK_PAR_H

#include <stddef.h>

typedef struct pk_par pk_par;

/* The most threads a pool has (pk_par_new caps the request). */
#define PK_PAR_MAX 64

/* How long an idle worker polls before it blocks (ns). */
#define PK_PAR_SPIN_NS 500000L

/* A pool of nthreads (the caller + nthreads − 1 workers); nthreads <= 1, no
 * threads support or a failure → NULL, which every function takes as the
 * serial pool. */
pk_par *pk_par_new(int nthreads);
void pk_par_free(pk_par *p);

/* Threads of the pool (1 for NULL). */
int pk_par_threads(const pk_par *p);

void pk_par_run(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx);

/* A CPU hint for spin loops. */
static inline void pk_par_pause(void)
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_ia32_pause();
#endif
}

/* Step *k (from 0) of a spin wait inside a part (see pk_par_run_parts):
 * a pause, and from the 64th step on a thrd_yield every 16th — on a machine
 * with more runnable threads than cores the thread waited for may be
 * descheduled, and a spinning waiter would hold the core it needs. */
void pk_par_wait_step(unsigned *k);

/* The same with nparts parts (>= 1; nothing when < 1): fn(ctx, t, nparts)
 * for t = 0 .. nparts−1, part 0 on the caller, the others claimed by
 * whichever thread is free first (the caller included) — parts of uneven
 * cost balance themselves.  NULL, busy or threadless pools run the nparts
 * parts in order on the caller.  Parts are claimed in increasing t, each
 * thread running one part at a time: a part may wait (spin) for parts with
 * a smaller t — they are all claimed by running threads, or done. */
void pk_par_run_parts(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx, int nparts);

/* [lo, hi) of n items for part t of nt, boundaries on multiples of align
 * (>= 1) except n itself: contiguous, disjoint, covering [0, n). */
void pk_par_range(size_t n, int t, int nt, size_t align, size_t *lo, size_t *hi);

#endif
