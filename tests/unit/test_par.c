/* test_par.c — the thread pool of core/base/par.h: every part t of a job runs
 * exactly once per pk_par_run, for many jobs in a row; what the parts wrote
 * (plain stores) is visible when pk_par_run returns and what the caller
 * wrote before is visible to the parts; the workers do take parts;
 * pk_par_run_parts runs any number of parts once each, and a part may wait
 * for the parts below it; an idle pool blocks (burns no CPU)
 * and wakes for the next job; nested runs and the NULL pool run serially;
 * pk_par_range tiles [0, n). */
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>
#include <threads.h>
#include <time.h>

#include "check.h"
#include "core/base/par.h"

#define MAXT 8
#define WORDS 256

typedef struct job {
    atomic_int runs[MAXT]; /* how often each part ran */
    atomic_int bad_nt;     /* parts that saw another nt than the pool's */
    atomic_int on_workers; /* parts run by another thread than the caller */
    thrd_t caller;
    int nt;
    uint64_t in;               /* written by the caller before the run */
    uint64_t out[MAXT][WORDS]; /* plain stores by the parts */
} job;

static void part(void *ctx, int t, int nt)
{
    job *j = ctx;
    if (nt != j->nt)
        atomic_fetch_add(&j->bad_nt, 1);
    atomic_fetch_add(&j->runs[t], 1);
    if (!thrd_equal(thrd_current(), j->caller))
        atomic_fetch_add(&j->on_workers, 1);
    for (int w = 0; w < WORDS; w++)
        j->out[t][w] = j->in * 1000003u + (uint64_t)(t * WORDS + w);
}

/* Run `calls` jobs on p and check every one right after it returns;
 * returns how many parts the workers ran. */
static int run_jobs(pk_par *p, int calls)
{
    static job j;
    const int nt = pk_par_threads(p);
    int wrong_runs = 0, wrong_data = 0;
    memset(&j, 0, sizeof j);
    j.nt = nt;
    j.caller = thrd_current();
    for (int k = 0; k < calls; k++) {
        for (int t = 0; t < nt; t++)
            atomic_store(&j.runs[t], 0);
        j.in = (uint64_t)k + 1;
        pk_par_run(p, part, &j);
        for (int t = 0; t < nt; t++) {
            wrong_runs += atomic_load(&j.runs[t]) != 1;
            for (int w = 0; w < WORDS; w++)
                wrong_data += j.out[t][w] != j.in * 1000003u + (uint64_t)(t * WORDS + w);
        }
    }
    CHECK_MSG(wrong_runs == 0, "%d parts ran not exactly once (nt %d)", wrong_runs, nt);
    CHECK_MSG(wrong_data == 0, "%d words stale after return (nt %d)", wrong_data, nt);
    CHECK(atomic_load(&j.bad_nt) == 0);
    return atomic_load(&j.on_workers);
}

static void test_each_part_once(void)
{
    for (int nt = 2; nt <= 4; nt++) {
        pk_par *p = pk_par_new(nt);
        CHECK(p != NULL);
        CHECK(pk_par_threads(p) == nt);
        /* back to back: the workers are spinning (the caller takes the
         * parts they have not claimed yet: on a loaded machine it may run
         * most of them) */
        int on_workers = run_jobs(p, 20000);
        printf("  %d threads: %d of %d parts on the workers\n", nt, on_workers, 20000 * (nt - 1));
        pk_par_free(p);
    }
}

typedef struct rendezvous {
    atomic_int started[MAXT];
    atomic_int timed_out;
} rendezvous;

/* Part 0 (the caller's) waits for every other part to start: they can
 * only run on the workers.  Bounded (2 s) so that a broken pool fails
 * instead of hanging. */
static void meet(void *ctx, int t, int nt)
{
    rendezvous *z = ctx;
    atomic_store(&z->started[t], 1);
    if (t != 0)
        return;
    double t0 = (double)clock() / CLOCKS_PER_SEC;
    for (int u = 1; u < nt; u++)
        while (!atomic_load(&z->started[u]))
            if ((double)clock() / CLOCKS_PER_SEC - t0 > 2) {
                atomic_store(&z->timed_out, 1);
                return;
            }
}

static void test_workers_take_parts(void)
{
    for (int nt = 2; nt <= 4; nt++) {
        pk_par *p = pk_par_new(nt);
        CHECK(p != NULL);
        rendezvous z;
        memset(&z, 0, sizeof z);
        pk_par_run(p, meet, &z);
        CHECK(!atomic_load(&z.timed_out));
        for (int t = 0; t < nt; t++)
            CHECK(atomic_load(&z.started[t]) == 1);
        pk_par_free(p);
    }
}

typedef struct many {
    atomic_int runs[64];
    atomic_int bad_nt;
    atomic_int timed_out;
    atomic_int done[64];
    int nparts;
} many;

/* Part t waits for every part below it to finish (the documented use:
 * they are claimed in order, so they are under way or done) — bounded, so
 * that a pool that breaks the order fails instead of hanging. */
static void many_part(void *ctx, int t, int nt)
{
    many *m = ctx;
    if (nt != m->nparts)
        atomic_fetch_add(&m->bad_nt, 1);
    double t0 = (double)clock() / CLOCKS_PER_SEC;
    unsigned k = 0;
    for (int u = 0; u < t; u++)
        while (!atomic_load(&m->done[u])) {
            pk_par_wait_step(&k);
            if ((double)clock() / CLOCKS_PER_SEC - t0 > 2) {
                atomic_store(&m->timed_out, 1);
                return;
            }
        }
    atomic_fetch_add(&m->runs[t], 1);
    atomic_store(&m->done[t], 1);
}

/* pk_par_run_parts: any number of parts (more or fewer than threads), each
 * exactly once, a part able to wait for the parts below it; NULL pool and
 * nparts < 1. */
static void test_run_parts(void)
{
    const int counts[] = {1, 2, 3, 7, 16, 64};
    pk_par *pools[2] = {NULL, pk_par_new(3)};
    int wrong = 0, bad_nt = 0, timed_out = 0;
    for (int q = 0; q < 2; q++)
        for (size_t c = 0; c < sizeof counts / sizeof *counts; c++)
            for (int rep = 0; rep < 200; rep++) {
                static many m;
                memset(&m, 0, sizeof m);
                m.nparts = counts[c];
                pk_par_run_parts(pools[q], many_part, &m, m.nparts);
                for (int t = 0; t < 64; t++)
                    wrong += atomic_load(&m.runs[t]) != (t < m.nparts);
                bad_nt += atomic_load(&m.bad_nt);
                timed_out += atomic_load(&m.timed_out);
            }
    CHECK_MSG(wrong == 0, "%d parts ran not exactly once", wrong);
    CHECK(bad_nt == 0);
    CHECK(timed_out == 0);
    static many none;
    pk_par_run_parts(pools[1], many_part, &none, 0);
    CHECK(atomic_load(&none.runs[0]) == 0);
    pk_par_free(pools[1]);
}

static void sleep_ms(long ms)
{
    thrd_sleep(&(struct timespec){.tv_sec = ms / 1000, .tv_nsec = (ms % 1000) * 1000000L}, NULL);
}

/* Jobs far apart: the workers have blocked on the condition variable in
 * between (the spin is PK_PAR_SPIN_NS = 0.5 ms) and must wake. */
static void test_wakes_after_blocking(void)
{
    pk_par *p = pk_par_new(3);
    CHECK(p != NULL);
    for (int k = 0; k < 5; k++) {
        sleep_ms(5);
        run_jobs(p, 3);
    }
    pk_par_free(p);
}

/* An idle pool blocks: over 200 ms with no job the process uses (far) less
 * than the 0.4 s of CPU three spinning workers would.  Bound 40 ms: the
 * workers block after 0.5 ms; the rest is noise of a loaded machine. */
static void test_idle_burns_no_cpu(void)
{
    pk_par *p = pk_par_new(4);
    CHECK(p != NULL);
    run_jobs(p, 10);
    sleep_ms(20); /* past the spin */
    clock_t c0 = clock();
    sleep_ms(200);
    double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    CHECK_MSG(cpu < 0.04, "idle pool used %.3f s CPU in 0.2 s", cpu);
    run_jobs(p, 10);
    pk_par_free(p);
}

/* Freed right away (workers spinning or not yet started), and freed idle
 * (workers blocked). */
static void test_free(void)
{
    for (int k = 0; k < 20; k++)
        pk_par_free(pk_par_new(2 + k % 3));
    pk_par *p = pk_par_new(4);
    CHECK(p != NULL);
    run_jobs(p, 2);
    sleep_ms(10);
    pk_par_free(p);
    pk_par_free(NULL);
}

static void test_null_pool(void)
{
    CHECK(pk_par_new(1) == NULL);
    CHECK(pk_par_new(0) == NULL);
    CHECK(pk_par_new(-3) == NULL);
    CHECK(pk_par_threads(NULL) == 1);
    CHECK(run_jobs(NULL, 10) == 0);
}

typedef struct nest {
    pk_par *p;
    job inner[MAXT];
} nest;

static void outer_part(void *ctx, int t, int nt)
{
    (void)nt;
    nest *n = ctx;
    n->inner[t].nt = 1; /* the pool is busy: the nested run is serial */
    pk_par_run(n->p, part, &n->inner[t]);
}

static void test_nested_run_is_serial(void)
{
    static nest n;
    memset(&n, 0, sizeof n);
    n.p = pk_par_new(3);
    CHECK(n.p != NULL);
    for (int t = 0; t < 3; t++)
        n.inner[t].in = 7;
    pk_par_run(n.p, outer_part, &n);
    for (int t = 0; t < 3; t++) {
        CHECK(atomic_load(&n.inner[t].runs[0]) == 1);
        CHECK(atomic_load(&n.inner[t].runs[1]) == 0);
        CHECK(atomic_load(&n.inner[t].bad_nt) == 0);
        CHECK(n.inner[t].out[0][5] == 7 * 1000003u + 5);
    }
    run_jobs(n.p, 5); /* still a working pool afterwards */
    pk_par_free(n.p);
}

static void test_range(void)
{
    const size_t ns[] = {0, 1, 7, 8, 9, 1000, 1003};
    const size_t aligns[] = {1, 4, 8};
    for (size_t a = 0; a < sizeof aligns / sizeof *aligns; a++)
        for (size_t m = 0; m < sizeof ns / sizeof *ns; m++)
            for (int nt = 1; nt <= 5; nt++) {
                size_t next = 0;
                for (int t = 0; t < nt; t++) {
                    size_t lo, hi;
                    pk_par_range(ns[m], t, nt, aligns[a], &lo, &hi);
                    CHECK(lo == next && lo <= hi);
                    CHECK(lo % aligns[a] == 0 || lo == ns[m]);
                    next = hi;
                }
                CHECK(next == ns[m]);
            }
}

int main(void)
{
    RUN(test_null_pool);
    RUN(test_range);
    RUN(test_each_part_once);
    RUN(test_workers_take_parts);
    RUN(test_run_parts);
    RUN(test_wakes_after_blocking);
    RUN(test_idle_burns_no_cpu);
    RUN(test_free);
    RUN(test_nested_run_is_serial);
    return check_summary();
}
