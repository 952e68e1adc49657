/* pack_model.c — the "model" record of a pack result; the contract is in
 * pack_model.h. */
#include "pack_model.h"

#include <string.h>

#include "api/schemas/option_table.h"
#include "pack_placer.h"

json_t *pk_pack_model_json(const pk_pack_job *job, const pk_pack_plan *plan)
{
    const pk_placer *placer = pk_placer_find(job->algorithm);
    const int history = placer && placer->has_history;
    return json_pack("{s:i,s:s,s:s,s:f,s:f,s:f,s:s,s:b,s:b,s:s}", "dim", job->dim, "quality",
                     pk_quality_names[job->quality], "algorithm", job->algorithm, "d_min",
                     job->d_min, "fines_mass_fraction", plan->mass_cut, "fines_phi_left_out",
                     plan->phi_mix - plan->phi_resolved, "fines", "matrix: below d_min, not placed",
                     /* placers keep contact counts (scalars), never the network */
                     "contacts_stored", 0,
                     /* a placer's φ(t), p(t) (pack_placer.h has_history) */
                     "history_stored", history, "friction", "not modelled (placement only)");
}
