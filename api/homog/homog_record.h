/* homog_record.h — per-step observables of a 'homogenize' run collected as
 * JSON arrays (written by pk_homog_record_write, summarised for the job
 * summary, kept so in checkpoints).  Tensor series
 * are split by component, named by 1-based indices ("11", "12", ... ;
 * "1111", ... for Ā); pk_homog_record_write joins them in the file. */
#ifndef PK_HOMOG_RECORD_H
#define PK_HOMOG_RECORD_H

#include <jansson.h>

#include "api/results/h5_observables.h"
#include "api/results/h5_result.h"
#include "api/results/h5_units.h"

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

/* The record and the audit in the result file (docs/result-format.md):
 * per-step series as H5MD time-dependent elements under
 * /observables/homogenize (tensors [S][d][d], Ā [S][d][d][d][d]) and
 * /observables/audit (steps audit_first.. on), time = (step + 1)/nstep;
 * final_state as [n][dim]; final_contacts as /connectivity/contacts;
 * units of u.  0 on success. */
int pk_homog_record_write(pk_h5 *h, json_t *rec, json_t *aud, int dim, size_t audit_first,
                          size_t nstep, const pk_units *u);

/* The unit of a homogenization observable ("homogenize/P") in units (a
 * pk_units), or NULL: a pk_h5_unit_fn. */
const char *pk_homog_unit_of(const char *name, const void *units);

#endif
