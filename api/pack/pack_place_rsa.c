/* pack_place_rsa.c — the 'rsa' placer: core/rsa/rsa with the job's "rsa"
 * options; the contract is in pack_placer.h. */
#include <stdio.h>

#include "pack_placer.h"

static int place_rsa(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                     const pk_run_ctx *run, pk_particles *p, pk_place_stats *st, char *err,
                     size_t errlen)
{
    pk_monitor *mon = run->mon;
    (void)plan;
    pk_rsa_params prm = {.delta_d = job->delta_d,
                         .max_failed_draws = job->opt.rsa.max_failed_draws,
                         .seed = job->seed,
                         .draws = (pk_rsa_draws)job->opt.rsa.draws,
                         .wall_gap = (pk_rsa_wall_gap)job->opt.rsa.wall_gap};
    pk_rsa_stats rs;
    if (pk_rsa_place(&job->box, sz->d, sz->species, sz->n, &prm, mon, p, &rs) != 0) {
        snprintf(err, errlen, "RSA placement failed (%s)", pk_stop_reason_name(rs.reason));
        return -1;
    }
    *st = (pk_place_stats){.reason = rs.reason,
                           .placed = rs.placed,
                           .requested = rs.requested,
                           .seconds = rs.seconds,
                           .walls_touch = prm.wall_gap == PK_RSA_WALL_GAP_NONE};
    st->obs = json_pack("{s:I,s:f,s:I}", "draws", (json_int_t)rs.draws, "draws_per_grain",
                        rs.placed ? (double)rs.draws / (double)rs.placed : 0.0, "max_failed_draws",
                        (json_int_t)prm.max_failed_draws);
    return 0;
}

/* In the order of pk_rsa_draws (core/rsa/rsa.h). */
static const char *const draws_names[] = {"open", "plain", NULL};
/* In the order of pk_rsa_wall_gap. */
static const char *const wall_gap_names[] = {"half", "none", NULL};
static const pk_option rsa_rows[] = {
    {"/rsa/max_failed_draws", PK_OPT_INTEGER, PK_OPT_FIELD(pk_rsa_options, max_failed_draws),
     .dflt = 1000000, .lo = 1, .hi = 1e10, PK_OPT_QUALITY(1e5, 1e7)},
    {"/rsa/draws", PK_OPT_ENUM, PK_OPT_FIELD(pk_rsa_options, draws), .names = draws_names},
    {"/rsa/wall_gap", PK_OPT_ENUM, PK_OPT_FIELD(pk_rsa_options, wall_gap), .names = wall_gap_names},
};
static const pk_option_table rsa_options =
    PK_OPT_TABLE("pack.inputs.schema.json", pk_rsa_options, rsa_rows, NULL);

const pk_placer pk_placer_rsa = {
    .name = "rsa", .options = &rsa_options, .check = NULL, .place = place_rsa};
