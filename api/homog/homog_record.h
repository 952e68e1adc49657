/* homog_record.h — per-step observables of a 'homogenize' run collected as
 * JSON arrays (written by pk_h5_obs_json under /observables/homogenize and
 * summarised for the job summary).  Tensor series are split by component,
 * named by 1-based indices ("11", "12", ... ; "1111", ... for Ā). */
#ifndef PK_HOMOG_RECORD_H
#define PK_HOMOG_RECORD_H

#include <jansson.h>

#include "core/homog/homog_audit.h"
#include "core/homog/homog_bc.h"
#include "core/homog/homog_tangent.h"

/* A new record object for an RVE of dimension dim. */
json_t *pk_homog_record_new(int dim, int with_tangent);
/* Append one step's figures (0 / -1 memory). */
int pk_homog_record_step(json_t *rec, int dim, const pk_homog_step *st);
/* Append one step's tangent (index = step number) or its failure status. */
int pk_homog_record_tangent(json_t *rec, int dim, size_t step, const double A[81],
                            const pk_tangent_info *info, int ok);

/* The audit's series (/observables/audit: per step, with its bounds) and
 * one step's figures (0 / -1 memory). */
json_t *pk_homog_record_audit_new(void);
int pk_homog_record_audit(json_t *aud, const pk_homog_audit *a);

#endif
