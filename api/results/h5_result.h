/* h5_result.h — packd result files, layout after H5MD 1.1 (docs/result-format.md).
 *
 *   /h5md                       version = [1,1]; /h5md/author (name: pk_h5_create),
 *                               /h5md/creator (name, version), /h5md/modules/units (system SI)
 *   /particles/grains/box       attrs dimension, boundary[dim] ("periodic"|"none"); dataset edges[dim]
 *   /particles/grains/position  [N][dim] float64, attr unit
 *   /particles/grains/radius    [N] float64, attr unit      (packd element; H5MD has none)
 *   /particles/grains/species   [N] int32 (size class, 0 = coarsest)
 *   /particles/grains/id        [N] int64 (H5MD identity 0..N-1)
 *   /parameters                 attrs process, seed, packd_version; datasets job (JSON text),
 *                               result_digest (result_digest.h; written by pk_h5_commit)
 *   /observables/<name>         scalars, arrays and strings written by the process
 *
 * A file is built in memory (HDF5's core driver), written by pk_h5_commit()
 * under a temporary name in the same directory with write(2), fsync'd and
 * renamed into place, so a reader never sees a half file, a crash leaves at
 * most a *.tmp.* file behind, and a full disk is an errno in the message
 * ("No space left on device") with the temporary file removed. */
#ifndef PK_H5_RESULT_H
#define PK_H5_RESULT_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"

typedef struct pk_h5 pk_h5;

/* The mode of a result file and of its sidecars (before the umask): the
 * owner and the group (the service's readers) read, others not. */
#define PK_RESULT_FILE_MODE 0640

/* Creates "<path>.tmp.<pid>" with /h5md/author name author (the job's owner
 * for a service job, the user for `packd run`; NULL or "" =
 * PK_H5_AUTHOR_UNKNOWN).  NULL on failure with a message in err. */
#define PK_H5_AUTHOR_UNKNOWN "unknown"
pk_h5 *pk_h5_create(const char *path, const char *author, char *err, size_t errlen);

int pk_h5_write_particles(pk_h5 *h, const pk_box *b, const pk_particles *p, const char *unit);
int pk_h5_write_parameters(pk_h5 *h, const char *process, const char *job_json, uint64_t seed);

/* Every writer below returns 0 or -1 and also remembers a failure in h (a
 * sticky error): a caller may write on without summing return codes, and
 * pk_h5_commit refuses a file one of whose writes failed ("writing <path>
 * failed", the temporary file removed).  pk_h5_failed tells so early. */
int pk_h5_failed(const pk_h5 *h);

/* Observables under /observables (name may contain '/' for sub-groups,
 * e.g. "grading/target_passing"); unit may be NULL (dimensionless). */
int pk_h5_obs_double(pk_h5 *h, const char *name, double v, const char *unit);
int pk_h5_obs_int(pk_h5 *h, const char *name, int64_t v);
int pk_h5_obs_string(pk_h5 *h, const char *name, const char *v);
int pk_h5_obs_doubles(pk_h5 *h, const char *name, const double *v, size_t n, const char *unit);
int pk_h5_obs_ints(pk_h5 *h, const char *name, const int64_t *v, size_t n);

/* Every member of a JSON object as observables under prefix ("rsa" →
 * /observables/rsa/<key>): reals → float64, integers → int64, strings,
 * booleans → int64 0/1, arrays of numbers → 1-d arrays, objects → sub-groups.
 * Other values are skipped.  0 on success. */
#include <jansson.h>
int pk_h5_obs_json(pk_h5 *h, const char *prefix, json_t *obj);
/* The same with a unit attribute on the numbers unit_of names: it gets the
 * observable's name ("edmd/delta_d_reached") and returns a unit string of
 * the H5MD units module ("mm", "N mm-2") or NULL (dimensionless). */
typedef const char *(*pk_h5_unit_fn)(const char *name, const void *ctx);
int pk_h5_obs_json_units(pk_h5 *h, const char *prefix, json_t *obj, pk_h5_unit_fn unit_of,
                         const void *ctx);

/* The unit string of a dimensionless number (the units module's numeric
 * factor alone): what a `time` that is no physical time carries. */
#define PK_H5_UNIT_NUMBER "1"

/* An n-d array (rank <= 5) at an absolute path ("/particles/rve/position/value"),
 * intermediate groups made; unit may be NULL.  0 on success. */
typedef enum { PK_H5_F64, PK_H5_I64, PK_H5_I32 } pk_h5_type;
int pk_h5_write_array(pk_h5 *h, const char *path, pk_h5_type type, int rank, const size_t *dims,
                      const void *data, const char *unit);
/* An H5MD time-dependent element at path: path/step int64[S], path/time
 * float64[S] with the unit time_unit (NULL: PK_H5_UNIT_NUMBER, the times
 * packd records are numbers: EDMD's reduced time, load fractions), path/value
 * of rank dims (dims[0] = S).
 * With clock (the path of an element already written), step and time are
 * hard links to clock's (H5MD shares them so).  0 on success. */
int pk_h5_time_element(pk_h5 *h, const char *path, const char *clock, const int64_t *step,
                       const double *time, const char *time_unit, pk_h5_type type, int rank,
                       const size_t *dims, const void *value, const char *unit);
/* A JSON history {step_key: [...], time_key: [...], name: [...], ...} as
 * time-dependent elements /observables/<prefix>/<name> (step: step_key's
 * values as integers, time: time_key's; the first element holds them, the
 * others link to it).  0 on success. */
int pk_h5_obs_history(pk_h5 *h, const char *prefix, json_t *hist, const char *step_key,
                      const char *time_key);
/* An H5MD connectivity dataset int64[n][2] at path with the attribute
 * particles_group, an object reference to the particles group the indices
 * number (e.g. "/particles/rve"). */
int pk_h5_connectivity(pk_h5 *h, const char *path, const int64_t *pairs, size_t n,
                       const char *particles_group);
/* A second name (hard link) for an existing object, e.g. a shared box group. */
int pk_h5_link(pk_h5 *h, const char *existing, const char *path);

/* Close, fsync and rename into place.  Frees h.  0 on success. */
int pk_h5_commit(pk_h5 *h, char *err, size_t errlen);
/* Close and remove the temporary file.  Frees h. */
void pk_h5_abort(pk_h5 *h);

/* Read the grains back (tests, `packd inspect`, homogenization input).
 * `p` is initialised here.  0 on success. */
int pk_h5_read_particles(const char *path, pk_box *b, pk_particles *p, char *err, size_t errlen);
/* The length unit of a result's grains (the unit attribute of
 * /particles/grains/position), "" and -1 when it has none. */
int pk_h5_read_unit(const char *path, char *unit, size_t n);

#endif
