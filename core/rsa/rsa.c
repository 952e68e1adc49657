/* rsa.c — random sequential addition, one grain at a time or, for runs of equal
 * grains, through the batched path.  Contract: core/rsa/rsa.h, core/rsa/README.md. */
#include "rsa.h"

#include <math.h>

#include "core/space/grid.h"
#include "core/base/rng.h"
#include "core/rsa/batch/rsa_batch.h"
#include "rsa_voxels.h"

/* Draws come from one voxel set (rsa_voxels.h) built for the smallest grain
 * still to place, so it serves the rest of the run and each placed grain is
 * marked once.  It is built only if it stays O(grains): voxels <= this many
 * per grain still to place (plus a constant); otherwise (e.g. a few fine
 * grains in a box 1000× their size) the plain draws are used.  A16 with
 * Δd 1 mm needs 26 per grain, Titscher's 150 mm specimen 37. */
#define VOXELS_PER_GRAIN 64
#define VOXELS_FREE 65536
/* and at most this many in all: 12 bytes a voxel, 1.6 GB (A16 with Δd 1 mm:
 * ~5·10⁶ grains); beyond, plain draws */
#define VOXELS_MAX ((uint64_t)1 << 27)

/* Marking covered sub-voxels costs more than it saves while most draws
 * succeed: it starts once a window of WINDOW placements took more than
 * COVER_AFTER draws per grain, or one grain failed COVER_AFTER_FAILS times. */
#define WINDOW 256
#define COVER_AFTER 6
#define COVER_AFTER_FAILS 4096

typedef struct segment {
    pk_rsa_vox vox;
    int on;
    int tried;     /* a set was built or refused for the grains from here on */
    int covering;  /* placed grains mark their exclusion zones */
    size_t marked; /* grains 0..marked-1 (in `out`) have marked the set */
    uint64_t win_draws, win_placed;
} segment;

/* Every grain placed and not yet marked marks its exclusion zone.  Marks are
 * optional for correctness (a bit left set only costs a draw), so a cancel
 * request may cut this short. */
static void mark_placed(segment *sg, const pk_particles *out, pk_monitor *mon, pk_progress *pg)
{
    sg->covering = 1;
    for (; sg->marked < out->n; sg->marked++) {
        pk_rsa_vox_cover(&sg->vox, &out->x[3 * sg->marked], out->r[sg->marked]);
        /* a coarse grain marks ~10⁵ voxels of a fine set: tick often */
        if ((sg->marked & 0x3f) == 0x3f && pk_monitor_tick(mon, pg, 0)) {
            sg->marked++;
            return;
        }
    }
}

/* Build the voxel set for grain i onwards, valid down to the smallest grain
 * (all bits set; the placed grains mark their zones once covering starts). */
static void begin_segment(segment *sg, const pk_box *b, const double *diameters, size_t i, size_t n,
                          double gap, double wall)
{
    sg->tried = 1;
    double r_valid = 0.5 * diameters[n - 1];
    uint64_t nv = pk_rsa_vox_count(b, r_valid, 0.5 * diameters[i], gap, wall);
    if (nv == 0 || nv > VOXELS_MAX || nv > (uint64_t)VOXELS_PER_GRAIN * (n - i) + VOXELS_FREE)
        return;
    if (pk_rsa_vox_init(&sg->vox, b, r_valid, 0.5 * diameters[i], gap, wall) != 0)
        return; /* out of memory for the set: plain draws still work */
    sg->on = 1;
    sg->covering = 0;
    sg->marked = 0;
    sg->win_draws = sg->win_placed = 0;
}

/* A batched run's entry hook (pk_rsa_batch_env.enter): the batched path has
 * sets of its own, so this one is freed; the grains after the run build a
 * new one. */
static int leave_segment(void *ctx)
{
    segment *sg = ctx;
    if (sg->on)
        pk_rsa_vox_free(&sg->vox);
    sg->on = sg->tried = 0;
    return 0;
}

/* 1 if the request is one pk_rsa_place serves (rsa.h). */
static int request_valid(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                         const pk_rsa_params *prm, const pk_particles *out)
{
    if (!b || !prm || !out || out->dim != b->dim || (n && (!diameters || !species)))
        return 0;
    if (!(prm->delta_d >= 0) || prm->max_failed_draws == 0 ||
        (prm->wall_gap != PK_RSA_WALL_GAP_HALF && prm->wall_gap != PK_RSA_WALL_GAP_NONE))
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!(diameters[i] > 0) || (i && diameters[i] > diameters[i - 1]))
            return 0; /* sizes must be positive and sorted largest first */
    return 1;
}

/* One call of pk_rsa_place: the grid of the grains present, the stream, the
 * progress and the voxel-set segment of the one-at-a-time draws. */
typedef struct rsa_run {
    const pk_box *b;
    const pk_rsa_params *prm;
    pk_monitor *mon;
    pk_particles *out;
    pk_rsa_stats *st;
    size_t n;
    double gap;  /* Δd */
    double wall; /* clearance kept at walls */
    pk_grid grid;
    pk_rng rng;
    pk_progress pg;
    double box_measure, solid;
    segment sg;
} rsa_run;

/* Set up the run for n grains after the grains already in out (which stay
 * obstacles).  -1 when out of memory (nothing left to free). */
static int open_run(rsa_run *u, const pk_box *b, const double *diameters, size_t n,
                    const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out, pk_rsa_stats *st)
{
    *u = (rsa_run){.b = b, .prm = prm, .mon = mon, .out = out, .st = st, .n = n};
    if (pk_particles_reserve(out, out->n + n) != 0)
        return -1;
    u->gap = prm->delta_d;
    /* the clearance kept at walls: Δd/2 (Titscher & Unger §6.3: the diameters
     * are enlarged by Δd), or none */
    u->wall = prm->wall_gap == PK_RSA_WALL_GAP_NONE ? 0 : 0.5 * u->gap;
    if (pk_grid_init_dense(&u->grid, b, 0.5 * diameters[n - 1], 0.5 * diameters[0], u->gap,
                           out->n + n) != 0)
        return -1;
    for (size_t j = 0; j < out->n; j++)
        pk_grid_insert(&u->grid, out, j);
    pk_rng_seed(&u->rng, prm->seed, 1);
    pk_monitor_begin(mon);
    u->box_measure = pk_box_measure(b);
    u->solid = pk_particles_solid_measure(out);
    u->pg = (pk_progress){.stage = "rsa", .total = n, .eta_s = -1};
    u->sg = (segment){.on = 0, .tried = prm->draws == PK_RSA_DRAWS_PLAIN};
    return 0;
}

/* The progress record brought up to the grains placed. */
static void note_progress(rsa_run *u)
{
    u->pg.done = u->st->placed;
    u->pg.fraction = (double)u->st->placed / (double)u->n;
    u->pg.phi = u->solid / u->box_measure;
}

/* Draw range per axis for a grain of radius r: walls keep the grain `wall`
 * away (Titscher & Unger §4).  0 when it fits in no position. */
static int draw_range(const pk_box *b, double r, double wall, double *lo, double *span)
{
    int fits = 1;
    for (int k = 0; k < b->dim; k++) {
        if (b->periodic[k]) {
            lo[k] = 0;
            span[k] = b->L[k];
        } else {
            lo[k] = r + wall;
            span[k] = b->L[k] - 2 * lo[k];
            if (span[k] < 0)
                fits = 0;
        }
    }
    return fits;
}

/* Draw positions for one grain of radius r until one overlaps nothing (x),
 * the draws fail max_failed_draws times in a row, the voxel set is
 * exhausted, or a stop is asked.  *failed: the failed draws. */
static pk_stop_reason draw_grain(rsa_run *u, double r, const double *lo, const double *span,
                                 double *x, uint64_t *failed)
{
    const pk_box *b = u->b;
    segment *sg = &u->sg;
    const uint64_t max_failed = u->prm->max_failed_draws;
    uint64_t nf = 0;
    for (;;) {
        int ok;
        if (sg->on) {
            int rc = pk_rsa_vox_draw(&sg->vox, &u->rng, x);
            if (rc < 0) {
                *failed = nf;
                return PK_STOP_SATURATED;
            }
            u->st->draws++;
            ok = rc == 0; /* rc 1: in a sub-voxel known to be covered */
            /* a grain larger than r_valid has a narrower range on walled axes */
            for (int k = 0; ok && k < b->dim; k++)
                if (!b->periodic[k] && (x[k] < lo[k] || x[k] > lo[k] + span[k]))
                    ok = 0;
            ok = ok && !pk_grid_overlaps(&u->grid, u->out, x, r);
        } else {
            for (int k = 0; k < b->dim; k++)
                x[k] = lo[k] + span[k] * pk_rng_uniform(&u->rng);
            u->st->draws++;
            ok = !pk_grid_overlaps(&u->grid, u->out, x, r);
        }
        if (ok)
            break;
        if (++nf >= max_failed)
            break;
        if (nf == COVER_AFTER_FAILS && sg->on && !sg->covering)
            mark_placed(sg, u->out, u->mon, &u->pg);
        if ((nf & 0xffff) == 0 && pk_monitor_tick(u->mon, &u->pg, 0))
            break;
    }
    *failed = nf;
    if (nf >= max_failed)
        return PK_STOP_MAX_FAILED_DRAWS;
    if (u->mon && u->mon->cancelled)
        return u->mon->cancelled == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
    return PK_STOP_COMPLETE;
}

/* After a placement that took failed + 1 draws: while covering, the grain
 * marks its zone; before, a window of WINDOW placements that took more than
 * COVER_AFTER draws per grain starts covering. */
static void after_placement(rsa_run *u, uint64_t failed)
{
    segment *sg = &u->sg;
    if (sg->on && sg->covering) {
        mark_placed(sg, u->out, u->mon, &u->pg);
    } else if (sg->on && (sg->win_draws += failed + 1, ++sg->win_placed == WINDOW)) {
        if (sg->win_draws > COVER_AFTER * WINDOW)
            mark_placed(sg, u->out, u->mon, &u->pg);
        sg->win_draws = sg->win_placed = 0;
    }
}

/* Place grain i (radius r, drawn in lo + [0, span]) one at a time: the voxel
 * set begun or brought up to date, the draws, the grid, the progress. */
static pk_stop_reason place_one(rsa_run *u, const double *diameters, int32_t species, size_t i,
                                double r, const double *lo, const double *span)
{
    segment *sg = &u->sg;
    if (!sg->tried && u->prm->draws == PK_RSA_DRAWS_OPEN)
        begin_segment(sg, u->b, diameters, i, u->n, u->gap, u->wall);
    if (sg->on && sg->covering && sg->marked < u->out->n)
        mark_placed(sg, u->out, u->mon, &u->pg); /* grains of a batched run before */
    double x[PK_MAXDIM] = {0, 0, 0};
    uint64_t failed;
    pk_stop_reason why = draw_grain(u, r, lo, span, x, &failed);
    if (why != PK_STOP_COMPLETE)
        return why;
    size_t j = pk_particles_push(u->out, x, r, species);
    if (j == (size_t)-1 || pk_grid_insert(&u->grid, u->out, j) != 0)
        return PK_STOP_ERROR;
    after_placement(u, failed);
    u->st->placed++;
    u->solid += pk_ball_measure(u->b->dim, r);
    note_progress(u); /* kept current: the draw loop's ticks report it too */
    if ((i & 0x3ff) == 0) {
        int c = pk_monitor_tick(u->mon, &u->pg, 0);
        if (c)
            return c == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
    }
    return PK_STOP_COMPLETE;
}

/* After a batched run that placed grains first.. out->n - 1: later (smaller)
 * grains see them in the grid. */
static pk_stop_reason grid_take_run(rsa_run *u, size_t first)
{
    for (size_t j = first; j < u->out->n; j++)
        if (pk_grid_insert(&u->grid, u->out, j) != 0)
            return PK_STOP_ERROR;
    return PK_STOP_COMPLETE;
}

int pk_rsa_place(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                 const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out, pk_rsa_stats *st)
{
    pk_rsa_stats local = {0};
    if (!st)
        st = &local;
    *st = (pk_rsa_stats){.reason = PK_STOP_ERROR, .requested = n};
    if (!request_valid(b, diameters, species, n, prm, out))
        return -1;
    double t0 = pk_wall_seconds();
    st->reason = PK_STOP_COMPLETE;
    if (n == 0)
        return 0;
    rsa_run u;
    if (open_run(&u, b, diameters, n, prm, mon, out, st) != 0)
        return -1;
    const pk_rsa_batch_env env = {.b = b,
                                  .prm = prm,
                                  .grid = &u.grid,
                                  .rng = &u.rng,
                                  .mon = mon,
                                  .pg = &u.pg,
                                  .box_measure = u.box_measure,
                                  .solid = &u.solid,
                                  .out = out,
                                  .st = st,
                                  .enter = leave_segment,
                                  .ctx = &u.sg};
    /* runs of equal grains go batched, the rest (and runs the batched path
     * declines) one at a time */
    size_t no_batch_below = prm->test.one_at_a_time ? SIZE_MAX : 0;
    for (size_t i = 0; i < n && st->reason == PK_STOP_COMPLETE; i++) {
        double r = 0.5 * diameters[i];
        double lo[PK_MAXDIM] = {0, 0, 0}, span[PK_MAXDIM] = {0, 0, 0};
        if (!draw_range(b, r, u.wall, lo, span)) {
            st->reason = PK_STOP_NO_ROOM;
            break;
        }
        if (i >= no_batch_below) {
            size_t run = 1;
            while (i + run < n && diameters[i + run] == diameters[i])
                run++;
            size_t first = out->n;
            pk_stop_reason why;
            if (pk_rsa_batch_place(&env, r, &species[i], run, lo, span, &why)) {
                if (why == PK_STOP_COMPLETE && i + run < n)
                    why = grid_take_run(&u, first);
                st->reason = why;
                i += run - 1;
                continue;
            }
            no_batch_below = i + run; /* the rest of this run goes one at a time too */
        }
        st->reason = place_one(&u, diameters, species[i], i, r, lo, span);
    }
    note_progress(&u);
    if (mon && !mon->cancelled)
        pk_monitor_tick(mon, &u.pg, 1);
    if (u.sg.on)
        pk_rsa_vox_free(&u.sg.vox);
    pk_grid_free(&u.grid);
    st->seconds = pk_wall_seconds() - t0;
    return st->reason == PK_STOP_ERROR ? -1 : 0;
}
