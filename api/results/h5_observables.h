/* h5_observables.h — one list of a process's scalar observables, written to
 * both the summary (JSON) and the result file (/observables, with units).
 *
 * The list is a pk_unit_row table (h5_units.h): each row an observable's name
 * ("phi_resolved", "timing/place_s": '/' makes a sub-object in JSON and a
 * sub-group in HDF5) and what it measures (PK_U_NONE for a count, a ratio or
 * a string).  The values sit in a JSON object under the same names; the
 * summary takes that object's members as they are, the file gets one dataset
 * per row.  A field of the summary without a row is caught by
 * tests/unit/test_pack_observables.c. */
#ifndef PK_H5_OBSERVABLES_H
#define PK_H5_OBSERVABLES_H

#include <jansson.h>

#include "h5_result.h"
#include "h5_units.h"

/* The value of name ("timing/place_s") in values, or NULL. */
json_t *pk_obs_value(json_t *values, const char *name);

/* Set name in values (sub-objects made as needed); takes the reference of v.
 * 0, or -1 (out of memory, or a path through a non-object). */
int pk_obs_set(json_t *values, const char *name, json_t *v);

/* Each row of rows (ending with {NULL}) with its value in values as
 * /observables/<name>: a real → float64 with the row's unit in u, an integer
 * → int64 (float64 when it has a unit), a string → a string.  A row without
 * a value is not written (not defined for this run: no φ target for a packing
 * grown until jammed); a value of another type is an error.  0 or -1. */
int pk_h5_obs_rows(pk_h5 *h, const pk_unit_row *rows, json_t *values, const pk_units *u);

/* The row of name in rows, or NULL. */
const pk_unit_row *pk_obs_row(const pk_unit_row *rows, const char *name);

#endif
