/* pack_model.h — what a 'pack' result models and what it leaves out: the
 * summary's "model" object and /observables/modelled (docs/presets.md). */
#ifndef PK_PACK_MODEL_H
#define PK_PACK_MODEL_H

#include <jansson.h>

#include "pack_job.h"

/* A new object: dim, quality, d_min and the fines below it left out as matrix
 * (their share of the mix's mass and of the box, φ_M − φ_eff of the targets),
 * and which optional records the placer stores (contact network, history). */
json_t *pk_pack_model_json(const pk_pack_job *job, const pk_pack_plan *plan);

#endif
