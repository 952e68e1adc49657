/* test_edmd_checkpoint.c — an EDMD run continued from a snapshot
 * (core/edmd/edmd_checkpoint.h) is a valid continuation: same grains, no
 * overlaps, the counters and history carried on, the jamming density of an
 * uninterrupted run; the snapshot survives its HDF5 file unchanged
 * (api/pack/edmd_checkpoint_h5.h) and a file of another job is refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "core/edmd/edmd.h"
#include "core/edmd/edmd_checkpoint.h"
#include "api/pack/edmd_checkpoint_h5.h"
#include "edmd_fixture.h"
#include "core/space/gap_audit.h"

#define N 400

/* Keeps the snapshot taken after `keep_after` events (the first one past). */
typedef struct keeper {
    uint64_t keep_after;
    pk_edmd_snapshot snap;
    int have;
} keeper;

static int keep(const pk_edmd_snapshot *s, void *ctx)
{
    keeper *k = ctx;
    if (k->have || (uint64_t)s->cnt[PK_EDMD_SNAP_EVENTS] < k->keep_after)
        return 0;
    if (pk_edmd_snapshot_alloc(&k->snap, s->n, s->dim) != 0)
        return -1;
    memcpy(k->snap.kin, s->kin, s->n * PK_EDMD_SNAP_KIN * sizeof *s->kin);
    memcpy(k->snap.perm, s->perm, s->n * sizeof *s->perm);
    memcpy(k->snap.scal, s->scal, sizeof s->scal);
    memcpy(k->snap.cnt, s->cnt, sizeof s->cnt);
    memcpy(k->snap.hist, s->hist, sizeof s->hist);
    k->snap.nhist = s->nhist;
    k->have = 1;
    return 0;
}

static void grains(pk_particles *p)
{
    pk_particles_init(p, 3, N);
    double x[3] = {0, 0, 0};
    for (int i = 0; i < N; i++)
        pk_particles_push(p, x, i % 2 ? 0.35 : 0.5, i % 2);
}

static void params(pk_edmd_params *prm)
{
    pk_edmd_params_default(prm);
    prm->until = PK_EDMD_UNTIL_JAMMED;
    prm->growth_rate = 0.05;
    prm->seed = 7;
}

static int overlaps(const pk_box *b, const pk_particles *p)
{
    pk_gap_report rep;
    if (pk_gap_audit(b, p, 0, 1e-9 * 0.7, 0.5, &rep) != 0)
        return -1;
    return (int)rep.pairs_below;
}

static void test_resume_continues_the_run(void)
{
    pk_particles p;
    grains(&p);
    pk_box b = edmd_fixture_periodic_box(&p, 0.5);
    pk_edmd_params prm;
    params(&prm);
    /* uninterrupted, snapshots at every window (interval ~0) */
    keeper k = {.keep_after = 40000};
    pk_edmd_checkpoint ck = {.interval_s = 1e-9, .save = keep, .ctx = &k};
    prm.checkpoint = &ck;
    pk_edmd_stats full;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &full) == 0);
    CHECK(ck.saved > 2 && k.have);
    CHECK(full.reason == PK_STOP_JAMMED);
    CHECK(!ck.resumed);
    pk_particles_free(&p);
    if (!k.have)
        return;
    uint64_t from = (uint64_t)k.snap.cnt[PK_EDMD_SNAP_EVENTS];
    CHECK(from >= 40000 && from < full.events);

    /* through the file: the same numbers back; another job's digest refused */
    char path[] = "/tmp/packd_ckpt_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    char err[300];
    CHECK(pk_edmd_ckpt_save(path, "job-a", &k.snap, err, sizeof err) == 0);
    pk_edmd_snapshot back;
    CHECK(pk_edmd_ckpt_load(path, "job-b", &back, err, sizeof err) == -1);
    CHECK(strstr(err, "another job") != NULL);
    CHECK(pk_edmd_ckpt_load(path, "job-a", &back, err, sizeof err) == 0);
    CHECK(back.n == N && back.dim == 3 && back.nhist == k.snap.nhist);
    CHECK(back.kin && !memcmp(back.kin, k.snap.kin, N * PK_EDMD_SNAP_KIN * sizeof(double)));
    CHECK(back.perm && !memcmp(back.perm, k.snap.perm, N * sizeof(int64_t)));
    CHECK(!memcmp(back.scal, k.snap.scal, sizeof back.scal));
    CHECK(!memcmp(back.cnt, k.snap.cnt, sizeof back.cnt));
    unlink(path);
    pk_edmd_snapshot none;
    CHECK(pk_edmd_ckpt_load(path, "job-a", &none, err, sizeof err) == 1); /* no file: start anew */

    /* resumed from the file's copy: a valid continuation */
    grains(&p);
    pk_edmd_checkpoint rk = {.resume = &back};
    params(&prm);
    prm.checkpoint = &rk;
    pk_edmd_stats res;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &res) == 0);
    CHECK(rk.resumed && rk.resumed_events == from);
    CHECK(rk.resumed_time > 0 && res.t_stop > rk.resumed_time);
    CHECK(res.events > from);
    CHECK(res.reason == PK_STOP_JAMMED);
    CHECK(overlaps(&b, &p) == 0);
    /* the same grains: radii are the targets scaled alike, species kept */
    for (size_t i = 0; i < p.n; i++)
        CHECK_MSG(fabs(p.r[i] / (i % 2 ? 0.35 : 0.5) - p.r[0] / 0.5) < 1e-9 &&
                      p.species[i] == (int32_t)(i % 2),
                  "grain %zu", i);
    CHECK_NEAR(res.phi, full.phi, 0.01);
    CHECK(res.nhist >= back.nhist);
    printf("  uninterrupted %llu events, phi %.4f; resumed at %llu: %llu events after, phi %.4f\n",
           (unsigned long long)full.events, full.phi, (unsigned long long)from,
           (unsigned long long)(res.events - from), res.phi);
    pk_particles_free(&p);
    pk_edmd_snapshot_free(&back);
    pk_edmd_snapshot_free(&k.snap);
}

/* A snapshot of another size is refused by the engine (the caller then
 * starts anew). */
static void test_resume_refuses_a_foreign_snapshot(void)
{
    pk_edmd_snapshot s;
    CHECK(pk_edmd_snapshot_alloc(&s, N - 1, 3) == 0);
    for (size_t i = 0; i < s.n; i++)
        s.perm[i] = (int64_t)i;
    pk_particles p;
    grains(&p);
    pk_box b = edmd_fixture_periodic_box(&p, 0.5);
    pk_edmd_params prm;
    params(&prm);
    pk_edmd_checkpoint rk = {.resume = &s};
    prm.checkpoint = &rk;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == -1);
    CHECK(!rk.resumed);
    pk_particles_free(&p);
    pk_edmd_snapshot_free(&s);
}

int main(void)
{
    RUN(test_resume_continues_the_run);
    RUN(test_resume_refuses_a_foreign_snapshot);
    return check_summary();
}
