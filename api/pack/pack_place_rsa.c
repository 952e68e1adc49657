/* pack_place_rsa.c — the 'rsa' placer: core/rsa/rsa with the job's "rsa" options. */
#include <stdio.h>
#include <string.h>

#include "pack_placer.h"

static int place_rsa(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                     pk_monitor *mon, pk_particles *p, pk_place_stats *st, char *err,
                     size_t errlen)
{
    (void)plan;
    json_t *opt = json_object_get(job->inputs, "rsa");
    const char *draws = json_string_value(json_object_get(opt, "draws")); /* "open" | "plain" */
    pk_rsa_params prm = {.delta_d = job->delta_d,
                         .max_failed_draws = (uint64_t)pk_json_int_or(opt, "max_failed_draws", 1000000),
                         .seed = job->seed,
                         .draws = draws && strcmp(draws, "plain") == 0 ? PK_RSA_DRAWS_PLAIN
                                                                       : PK_RSA_DRAWS_OPEN};
    pk_rsa_stats rs;
    if (pk_rsa_place(&job->box, sz->d, sz->species, sz->n, &prm, mon, p, &rs) != 0) {
        snprintf(err, errlen, "RSA placement failed (%s)", pk_stop_reason_name(rs.reason));
        return -1;
    }
    *st = (pk_place_stats){.reason = rs.reason, .placed = rs.placed, .requested = rs.requested,
                           .seconds = rs.seconds};
    st->obs = json_pack("{s:I,s:f,s:I}", "draws", (json_int_t)rs.draws, "draws_per_grain",
                        rs.placed ? (double)rs.draws / (double)rs.placed : 0.0,
                        "max_failed_draws", (json_int_t)prm.max_failed_draws);
    return 0;
}

const pk_placer pk_placer_rsa = {.name = "rsa", .check = NULL, .place = place_rsa};
