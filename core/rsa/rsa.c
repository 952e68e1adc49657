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

int pk_rsa_place(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                 const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out, pk_rsa_stats *st)
{
    pk_rsa_stats local = {0};
    if (!st)
        st = &local;
    *st = (pk_rsa_stats){.reason = PK_STOP_ERROR, .requested = n};
    if (!b || !prm || !out || out->dim != b->dim || (n && (!diameters || !species)))
        return -1;
    if (!(prm->delta_d >= 0) || prm->max_failed_draws == 0 ||
        (prm->wall_gap != PK_RSA_WALL_GAP_HALF && prm->wall_gap != PK_RSA_WALL_GAP_NONE))
        return -1;
    for (size_t i = 0; i < n; i++)
        if (!(diameters[i] > 0) || (i && diameters[i] > diameters[i - 1]))
            return -1; /* sizes must be positive and sorted largest first */

    double t0 = pk_wall_seconds();
    st->reason = PK_STOP_COMPLETE;
    if (n == 0)
        return 0;
    if (pk_particles_reserve(out, out->n + n) != 0)
        return -1;

    const double gap = prm->delta_d;
    /* the clearance kept at walls: Δd/2 (Titscher & Unger §6.3: the diameters
     * are enlarged by Δd), or none */
    const double wall = prm->wall_gap == PK_RSA_WALL_GAP_NONE ? 0 : 0.5 * gap;
    pk_grid grid;
    if (pk_grid_init(&grid, b, 0.5 * diameters[n - 1], 0.5 * diameters[0], gap, out->n + n) != 0)
        return -1;
    for (size_t j = 0; j < out->n; j++) /* grains already present stay obstacles */
        pk_grid_insert(&grid, out, j);

    pk_rng rng;
    pk_rng_seed(&rng, prm->seed, 1);
    pk_monitor_begin(mon);
    double box_measure = pk_box_measure(b);
    double solid = pk_particles_solid_measure(out);
    pk_progress pg = {.stage = "rsa", .total = n, .eta_s = -1};

    segment sg = {.on = 0, .tried = prm->draws == PK_RSA_DRAWS_PLAIN};
    size_t no_batch_below = prm->test.one_at_a_time ? SIZE_MAX : 0;
    const pk_rsa_batch_env env = {.b = b,
                                  .prm = prm,
                                  .grid = &grid,
                                  .rng = &rng,
                                  .mon = mon,
                                  .pg = &pg,
                                  .box_measure = box_measure,
                                  .solid = &solid,
                                  .out = out,
                                  .st = st,
                                  .enter = leave_segment,
                                  .ctx = &sg};
    for (size_t i = 0; i < n; i++) {
        double r = 0.5 * diameters[i];
        /* Draw range per axis: walls keep the grain `wall` away (Titscher & Unger §4). */
        double lo[PK_MAXDIM] = {0, 0, 0}, span[PK_MAXDIM] = {0, 0, 0};
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
        if (!fits) {
            st->reason = PK_STOP_NO_ROOM;
            break;
        }
        size_t run = 1;
        while (i >= no_batch_below && i + run < n && diameters[i + run] == diameters[i])
            run++;
        size_t first = out->n;
        pk_stop_reason why;
        if (i >= no_batch_below && pk_rsa_batch_place(&env, r, &species[i], run, lo, span, &why)) {
            for (size_t j = first; why == PK_STOP_COMPLETE && i + run < n && j < out->n; j++)
                if (pk_grid_insert(&grid, out, j) != 0)
                    why = PK_STOP_ERROR; /* later (smaller) grains see the run's grains */
            if (why != PK_STOP_COMPLETE) {
                st->reason = why;
                break;
            }
            i += run - 1;
            continue;
        }
        if (i >= no_batch_below)
            no_batch_below = i + run; /* the rest of this run goes one at a time too */
        if (!sg.tried && prm->draws == PK_RSA_DRAWS_OPEN)
            begin_segment(&sg, b, diameters, i, n, gap, wall);
        if (sg.on && sg.covering && sg.marked < out->n)
            mark_placed(&sg, out, mon, &pg); /* grains of a batched run before */
        uint64_t failed = 0;
        double x[PK_MAXDIM] = {0, 0, 0};
        int saturated = 0;
        for (;;) {
            int ok;
            if (sg.on) {
                int rc = pk_rsa_vox_draw(&sg.vox, &rng, x);
                if (rc < 0) {
                    saturated = 1;
                    break;
                }
                st->draws++;
                ok = rc == 0; /* rc 1: in a sub-voxel known to be covered */
                /* a grain larger than r_valid has a narrower range on walled axes */
                for (int k = 0; ok && k < b->dim; k++)
                    if (!b->periodic[k] && (x[k] < lo[k] || x[k] > lo[k] + span[k]))
                        ok = 0;
                ok = ok && !pk_grid_overlaps(&grid, out, x, r);
            } else {
                for (int k = 0; k < b->dim; k++)
                    x[k] = lo[k] + span[k] * pk_rng_uniform(&rng);
                st->draws++;
                ok = !pk_grid_overlaps(&grid, out, x, r);
            }
            if (ok)
                break;
            if (++failed >= prm->max_failed_draws)
                break;
            if (failed == COVER_AFTER_FAILS && sg.on && !sg.covering)
                mark_placed(&sg, out, mon, &pg);
            if ((failed & 0xffff) == 0 && pk_monitor_tick(mon, &pg, 0))
                break;
        }
        if (saturated) {
            st->reason = PK_STOP_SATURATED;
            break;
        }
        if (failed >= prm->max_failed_draws) {
            st->reason = PK_STOP_MAX_FAILED_DRAWS;
            break;
        }
        if (mon && mon->cancelled) {
            st->reason = mon->cancelled == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
            break;
        }
        size_t j = pk_particles_push(out, x, r, species[i]);
        if (j == (size_t)-1 || pk_grid_insert(&grid, out, j) != 0) {
            st->reason = PK_STOP_ERROR;
            break;
        }
        if (sg.on && sg.covering) {
            mark_placed(&sg, out, mon, &pg);
        } else if (sg.on && (sg.win_draws += failed + 1, ++sg.win_placed == WINDOW)) {
            if (sg.win_draws > COVER_AFTER * WINDOW)
                mark_placed(&sg, out, mon, &pg);
            sg.win_draws = sg.win_placed = 0;
        }
        st->placed++;
        solid += pk_ball_measure(b->dim, r);
        /* kept current: the draw loop's ticks report it too */
        pg.done = st->placed;
        pg.fraction = (double)st->placed / (double)n;
        pg.phi = solid / box_measure;
        if ((i & 0x3ff) == 0) {
            int c = pk_monitor_tick(mon, &pg, 0);
            if (c) {
                st->reason = c == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
                break;
            }
        }
    }
    pg.done = st->placed;
    pg.fraction = (double)st->placed / (double)n;
    pg.phi = solid / box_measure;
    if (mon && !mon->cancelled)
        pk_monitor_tick(mon, &pg, 1);
    if (sg.on)
        pk_rsa_vox_free(&sg.vox);
    pk_grid_free(&grid);
    st->seconds = pk_wall_seconds() - t0;
    return st->reason == PK_STOP_ERROR ? -1 : 0;
}
