/* par.c — the persistent thread pool of the relaxations' parallel sections.
 * Contract: core/base/par.h. */
#include "par.h"

void pk_par_range(size_t n, int t, int nt, size_t align, size_t *lo, size_t *hi)
{
    size_t units = (n + align - 1) / align; /* whole groups of align items */
    size_t a = units * (size_t)t / (size_t)nt * align,
           b = units * (size_t)(t + 1) / (size_t)nt * align;
    *lo = a < n ? a : n;
    *hi = b < n ? b : n;
}

#ifdef __STDC_NO_THREADS__

pk_par *pk_par_new(int nthreads)
{
    (void)nthreads;
    return NULL;
}

void pk_par_free(pk_par *p) { (void)p; }

int pk_par_threads(const pk_par *p)
{
    (void)p;
    return 1;
}

void pk_par_run(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx)
{
    (void)p;
    fn(ctx, 0, 1);
}

void pk_par_run_parts(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx, int nparts)
{
    (void)p;
    for (int t = 0; t < nparts; t++)
        fn(ctx, t, nparts);
}

void pk_par_wait_step(unsigned *k)
{
    pk_par_pause();
    ++*k;
}

#else

#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <threads.h>

#include "progress.h"

struct pk_par {
    int nt;
    void (*fn)(void *ctx, int t, int nt); /* the job: written before claim is reset */
    void *ctx;
    atomic_uint gen;        /* job counter: a worker looks for parts when it changes */
    _Atomic uint64_t claim; /* the job's parts << 32 | the next part to claim: one
                               word, so a claim always sees its own job's count */
    atomic_int done;        /* parts finished by the workers */
    atomic_int sleepers;    /* workers blocked (or about to) on cnd */
    atomic_int stop;
    atomic_flag busy; /* a job is running: nested/concurrent runs go serial */
    mtx_t mtx;
    cnd_t cnd;
    thrd_t thr[PK_PAR_MAX];
};

void pk_par_wait_step(unsigned *k)
{
    pk_par_pause();
    if (++*k >= 64 && *k % 16 == 0)
        thrd_yield();
}

/* Polls between clock reads: a pause is ~10–150 cycles, so a few µs. */
#define POLLS 64
/* A spinning worker yields its core this often (s). */
#define YIELD_S 50e-6

/* Wait until the job counter moves past seen; returns its new value. */
static unsigned wait_job(pk_par *p, unsigned seen)
{
    const double t0 = pk_wall_seconds();
    double yielded = t0;
    for (;;) {
        for (int k = 0; k < POLLS; k++) {
            unsigned g = atomic_load_explicit(&p->gen, memory_order_acquire);
            if (g != seen)
                return g;
            pk_par_pause();
        }
        double now = pk_wall_seconds();
        if (now - t0 > 1e-9 * (double)PK_PAR_SPIN_NS)
            break;
        if (now - yielded > YIELD_S) { /* another process may want the core */
            thrd_yield();
            yielded = now;
        }
    }
    /* Block.  sleepers is raised before gen is read again and pk_par_run
     * bumps gen before it reads sleepers (both seq_cst): either this thread
     * sees the new job, or the runner sees a sleeper and broadcasts under
     * the mutex this thread holds until cnd_wait releases it. */
    mtx_lock(&p->mtx);
    atomic_fetch_add(&p->sleepers, 1);
    unsigned g;
    while ((g = atomic_load(&p->gen)) == seen)
        cnd_wait(&p->cnd, &p->mtx);
    atomic_fetch_sub(&p->sleepers, 1);
    mtx_unlock(&p->mtx);
    return g;
}

/* Claim the next part of the current job: its index in *t and the job's
 * number of parts in *nparts; 0 when none is left.  Failed claims bump the
 * low word too (a few per job: no carry into the count). */
static int claim(pk_par *p, int *t, int *nparts)
{
    uint64_t w = atomic_fetch_add_explicit(&p->claim, 1, memory_order_acq_rel);
    *t = (int)(uint32_t)w;
    *nparts = (int)(w >> 32);
    return *t < *nparts;
}

/* Parts are claimed, not assigned: whoever takes part t runs it (the
 * results may not depend on the thread), so the caller never waits for a
 * worker that is asleep or not scheduled — it runs that part itself — only
 * for parts already under way.  A worker that claims late may take a part
 * of the next job: legitimate, fn and ctx are read after the claim (acquire
 * of the caller's release of claim) and the job cannot end before the part
 * is done. */
static int worker(void *vp)
{
    pk_par *p = vp;
    unsigned seen = 0;
    for (;;) {
        seen = wait_job(p, seen);
        if (atomic_load_explicit(&p->stop, memory_order_acquire))
            return 0;
        for (int t, nparts; claim(p, &t, &nparts);) {
            p->fn(p->ctx, t, nparts);
            atomic_fetch_add_explicit(&p->done, 1, memory_order_release);
        }
    }
}

/* Publish a new job counter value and wake blocked workers. */
static void bump(pk_par *p)
{
    atomic_fetch_add(&p->gen, 1);
    if (atomic_load(&p->sleepers) > 0) {
        mtx_lock(&p->mtx);
        cnd_broadcast(&p->cnd);
        mtx_unlock(&p->mtx);
    }
}

static void stop_workers(pk_par *p, int started)
{
    atomic_store_explicit(&p->stop, 1, memory_order_release);
    bump(p);
    for (int k = 0; k < started; k++)
        thrd_join(p->thr[k], NULL);
}

pk_par *pk_par_new(int nthreads)
{
    if (nthreads <= 1)
        return NULL;
    if (nthreads > PK_PAR_MAX)
        nthreads = PK_PAR_MAX;
    pk_par *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->nt = nthreads;
    atomic_init(&p->gen, 0);
    atomic_init(&p->claim, 0);
    atomic_init(&p->done, 0);
    atomic_init(&p->sleepers, 0);
    atomic_init(&p->stop, 0);
    atomic_flag_clear(&p->busy);
    if (mtx_init(&p->mtx, mtx_plain) != thrd_success) {
        free(p);
        return NULL;
    }
    if (cnd_init(&p->cnd) != thrd_success) {
        mtx_destroy(&p->mtx);
        free(p);
        return NULL;
    }
    for (int k = 0; k < nthreads - 1; k++) {
        if (thrd_create(&p->thr[k], worker, p) != thrd_success) {
            stop_workers(p, k);
            cnd_destroy(&p->cnd);
            mtx_destroy(&p->mtx);
            free(p);
            return NULL;
        }
    }
    return p;
}

void pk_par_free(pk_par *p)
{
    if (!p)
        return;
    stop_workers(p, p->nt - 1);
    cnd_destroy(&p->cnd);
    mtx_destroy(&p->mtx);
    free(p);
}

int pk_par_threads(const pk_par *p) { return p ? p->nt : 1; }

/* nparts parts on p; when p is busy (a nested or concurrent run) or NULL,
 * serial_parts (nparts, or 1: pk_par_run) on the caller instead. */
static void run(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx, int nparts,
                int serial_parts)
{
    if (nparts < 1)
        return;
    if (!p || atomic_flag_test_and_set_explicit(&p->busy, memory_order_acquire)) {
        for (int t = 0; t < serial_parts; t++)
            fn(ctx, t, serial_parts);
        return;
    }
    p->fn = fn;
    p->ctx = ctx;
    atomic_store_explicit(&p->done, 0, memory_order_relaxed);
    /* part 0 is the caller's */
    atomic_store_explicit(&p->claim, (uint64_t)nparts << 32 | 1, memory_order_release);
    bump(p);
    fn(ctx, 0, nparts);
    int mine = 1; /* parts run here */
    for (int t, n; claim(p, &t, &n); mine++)
        fn(ctx, t, n);
    for (unsigned k = 0; atomic_load_explicit(&p->done, memory_order_acquire) < nparts - mine;)
        pk_par_wait_step(&k); /* the worker may be waiting for this core */
    atomic_flag_clear_explicit(&p->busy, memory_order_release);
}

void pk_par_run(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx)
{
    run(p, fn, ctx, p ? p->nt : 1, 1);
}

void pk_par_run_parts(pk_par *p, void (*fn)(void *ctx, int t, int nt), void *ctx, int nparts)
{
    run(p, fn, ctx, nparts, nparts);
}

#endif
