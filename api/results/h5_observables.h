/* h5_observables.h — one list of a process's observables, from which its
 * summary (JSON), its result file (/observables, with units) and the
 * summary's "units" member are all written.
 *
 * Each row names a summary member ("phi_resolved", "timing/place_s": '/'
 * makes a sub-object in JSON and a sub-group in HDF5), what it measures
 * (PK_U_NONE for a count, a ratio, a flag or a string), how it reaches the
 * file and where (under /observables; NULL: the same name).  A process keeps
 * its values in one JSON object under the rows' names; the summary takes
 * that object's members as they are.  The list hangs in the process table
 * (api/process.h); tests/unit/test_observables.c runs every process and
 * fails when a summary field has no row, no twin in the file or no unit. */
#ifndef PK_H5_OBSERVABLES_H
#define PK_H5_OBSERVABLES_H

#include <jansson.h>

#include "h5_result.h"
#include "h5_units.h"

typedef enum {
    /* one value (number, string, flag): the summary member and the dataset
     * /observables/<file>, written by pk_h5_obs_rows */
    PK_OBS_SCALAR,
    /* written by the process's own record (an H5MD element, an array, a
     * group); the summary holds a view of it (its last step, its steps) */
    PK_OBS_RECORD,
    /* in the file only (a series not summarised): the row gives its unit */
    PK_OBS_FILE,
    /* how the job ran (threads, MPI ranks, wall time): the summary's alone,
     * the file's bits being the same for any */
    PK_OBS_RUN
} pk_obs_form;

typedef struct pk_obs_row {
    const char *name; /* the summary member; PK_OBS_FILE: the file path */
    pk_unit_kind kind;
    pk_obs_form form;
    const char *file; /* its path under /observables; NULL: name */
} pk_obs_row;

/* The path of row under /observables. */
const char *pk_obs_file(const pk_obs_row *row);

/* The value of name ("timing/place_s") in values, or NULL. */
json_t *pk_obs_value(json_t *values, const char *name);

/* Set name in values (sub-objects made as needed); takes the reference of v.
 * 0, or -1 (out of memory, or a path through a non-object). */
int pk_obs_set(json_t *values, const char *name, json_t *v);

/* Each PK_OBS_SCALAR row of rows (ending with {NULL}) with its value in
 * values as /observables/<file>: a real → float64 with the row's unit in u,
 * an integer → int64 (float64 when it has a unit), a flag → int64 0/1, a
 * string → a string.  A row without a value is not written (not defined for
 * this run: no φ target for a packing grown until jammed); a value of
 * another type is an error.  0 or -1. */
int pk_h5_obs_rows(pk_h5 *h, const pk_obs_row *rows, json_t *values, const pk_units *u);

/* The row whose summary member is name, or NULL (PK_OBS_FILE rows are
 * not summary members). */
const pk_obs_row *pk_obs_row_named(const pk_obs_row *rows, const char *name);

/* The unit in u of the dataset or element at path (under /observables:
 * "homogenize/P"), or NULL: the row whose file is path. */
const char *pk_obs_unit_at(const pk_obs_row *rows, const char *path, const pk_units *u);

/* The summary's "units": {name: unit string} for each row with a unit
 * whose member summary holds (a new object; the dashboard groups by it). */
json_t *pk_obs_units_json(const pk_obs_row *rows, json_t *summary, const pk_units *u);

#endif
