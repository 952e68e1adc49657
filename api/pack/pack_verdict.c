/* pack_verdict.c — what a packing says of itself (api/job_verdict.h):
 * complete, short of its target by the user's choice (warnings), or failed. */
#include <math.h>

#include "api/job_verdict.h"
#include "pack_placer.h"

/* Every position and radius a finite number: the index of the first that is
 * not, or (size_t)-1. */
static size_t first_non_finite(const pk_particles *p)
{
    for (size_t i = 0; i < p->n; i++) {
        if (!isfinite(p->r[i]))
            return i;
        for (int k = 0; k < 3; k++)
            if (!isfinite(p->x[3 * i + k]))
                return i;
    }
    return (size_t)-1;
}

const char *pk_place_termination(const pk_place_stats *st)
{
    return st->termination ? st->termination : pk_stop_reason_name(st->reason);
}

void pk_pack_verdict(const pk_pack_job *job, const pk_pack_plan *plan, const pk_place_stats *st,
                     const pk_particles *p, const pk_gap_report *gap, double phi, double delta_d,
                     json_t *summary)
{
    const char *why = pk_place_termination(st);
    int done = st->reason == PK_STOP_COMPLETE || st->goal_reached;
    json_object_set_new(summary, "complete", json_boolean(done && !st->warning[0]));
    size_t bad = first_non_finite(p);
    if (bad != (size_t)-1 || !isfinite(phi))
        pk_verdict_fail(summary, "non-finite numbers in the result (grain %zu of %zu, φ %g)", bad,
                        p->n, phi);
    switch (st->reason) {
    case PK_STOP_WALL_TIME:
        if (st->phi_own)
            pk_verdict_fail(summary,
                            "ran out of wall time (limits.wall_time_s = %g s): %zu of %zu grains "
                            "placed, φ %.4g (the partial packing)",
                            job->wall_time_s, st->placed, st->requested, phi);
        else
            pk_verdict_fail(
                summary,
                "ran out of wall time (limits.wall_time_s = %g s): %zu of %zu grains placed, "
                "φ %.4g of the target %.4g",
                job->wall_time_s, st->placed, st->requested, phi, plan->phi_resolved);
        break;
    case PK_STOP_CANCELLED:
        if (st->phi_own)
            pk_verdict_fail(summary, "cancelled: %zu of %zu grains placed, φ %.4g", st->placed,
                            st->requested, phi);
        else
            pk_verdict_fail(summary,
                            "cancelled: %zu of %zu grains placed, φ %.4g of the target %.4g",
                            st->placed, st->requested, phi, plan->phi_resolved);
        break;
    case PK_STOP_ERROR:
        pk_verdict_fail(summary, "the placer stopped on an error after %zu of %zu grains",
                        st->placed, st->requested);
        break;
    default:
        if (st->warning[0]) /* the placer's own sentence says what fell short */
            break;
        if (!done && st->requested)
            pk_verdict_warn(summary,
                            "saturated: φ %.4g reached of the target %.4g (%s stopped: %s), %zu of "
                            "%zu grains placed",
                            phi, plan->phi_resolved, job->algorithm, why, st->placed,
                            st->requested);
        else if (!done) /* tetfill to a φ target: no count asked */
            pk_verdict_warn(summary,
                            "saturated: φ %.4g reached of the target %.4g (%s stopped: %s), %zu "
                            "grains placed",
                            phi, plan->phi_resolved, job->algorithm, why, st->placed);
        break;
    }
    /* after the stop's own sentence: a run stopped by its wall time or a cancel
     * says so first, its audit figures follow */
    if (gap->pairs_below || gap->walls_below)
        pk_verdict_fail(
            summary,
            "the gap audit found %zu pairs closer than Δd = %g (smallest gap %g) and "
            "%zu grains beyond their wall clearance: the packing breaks its own contract",
            gap->pairs_below, delta_d, gap->min_gap, gap->walls_below);
    if (st->warning[0])
        pk_verdict_warn(summary, "%s", st->warning);
}
