/* pack_model.c — the "model" record of a pack result; the contract is in
 * pack_model.h. */
#include "pack_model.h"

#include <string.h>

#include "api/schemas/option_table.h"

json_t *pk_pack_model_json(const pk_pack_job *job, const pk_pack_plan *plan)
{
    const int edmd = !strcmp(job->algorithm, "edmd");
    return json_pack("{s:i,s:s,s:s,s:f,s:f,s:f,s:s,s:b,s:b,s:s}", "dim", job->dim, "quality",
                     pk_quality_names[job->quality], "algorithm", job->algorithm, "d_min",
                     job->d_min, "fines_mass_fraction", plan->mass_cut, "fines_phi_left_out",
                     plan->phi_mix - plan->phi_resolved, "fines", "matrix: below d_min, not placed",
                     /* EDMD keeps contact counts (scalars), never the network */
                     "contacts_stored", 0,
                     /* EDMD's φ(t), p(t): at most PK_EDMD_HIST_MAX samples */
                     "history_stored", edmd, "friction", "not modelled (placement only)");
}
