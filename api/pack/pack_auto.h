/* pack_auto.h — "algorithm": "auto" of the 'pack' process: the placer chosen
 * for the job and why (docs/presets.md).
 *
 * Rule: a mesh domain → tetfill (the only placer of a mesh); "edmd":
 * {"until": "jammed"} → edmd (only EDMD jams); else rsa when the target
 * φ_eff, counted with the Δd shells, lies below the threshold, edmd above.
 * The threshold is RSA's measured reach for the grading's size spread
 * d_max/d_min (interpolated in ln spread), PK_AUTO_REACH_MARGIN below it
 * (RSA slows sharply in the last few hundredths: the measured break-even
 * with EDMD sits there), capped at PK_AUTO_BREAK_EVEN, the break-even of wide
 * gradings whose reach lies beyond it (measured ≈ 0.63 for A16 above 2 mm;
 * Titscher & Unger: 62.5 %). */
#ifndef PK_PACK_AUTO_H
#define PK_PACK_AUTO_H

#include <jansson.h>

#include "pack_job.h"

#define PK_AUTO_BREAK_EVEN 0.625
#define PK_AUTO_REACH_MARGIN 0.03

/* RSA's reach φ_eff (measured, docs/presets.md) for a grading whose
 * resolved sizes span d_max/d_min = spread, in dim 2 or 3. */
double pk_auto_rsa_reach(int dim, double spread);

/* Resolve "auto" in a parsed job whose plan is made: sets job->algorithm and
 * job->choice, refills the chosen placer's options from inputs and remakes
 * the plan when the choice is not the provisional rsa.  Returns the number
 * of errors appended (the new plan's).  Does nothing unless job->choice.requested. */
size_t pk_pack_auto_resolve(json_t *inputs, pk_pack_job *job, pk_pack_plan *plan,
                            pk_schema_errors *errs);

/* The choice as a JSON object (new reference; NULL when not requested):
 * algorithm, reason, threshold, phi_target_shell, size_spread. */
json_t *pk_pack_auto_json(const pk_pack_job *job);

#endif
