/* homog_checkpoint.h — a homogenization's load path saved after a committed
 * step, so a re-queued job resumes from its last saved step instead of step
 * 0.  The file (api/results/checkpoint_h5.h) holds the committed state (F̄, centres,
 * contact keys, rotations, friction history), the per-step record so far (as
 * JSON text), the counters, the last tangent and the last step's report. */
#ifndef PK_HOMOG_CHECKPOINT_H
#define PK_HOMOG_CHECKPOINT_H

#include <jansson.h>
#include <stddef.h>

#include "core/homog/homog_bc.h"

typedef struct pk_homog_ckpt {
    size_t done, not_converged, total_iter, max_iter_step;
    int have_A;
    double A[81];
    pk_homog_step last; /* the report of step done − 1 */
} pk_homog_ckpt;

/* 0, or -1 with err. */
int pk_homog_ckpt_save(const char *path, const char *digest, const pk_homog_ckpt *c,
                       const pk_homog_state *com, json_t *rec, char *err, size_t errlen);

/* 0: c, com (initialised for the same RVE: its n must match) and *rec (new
 * reference) restored; 1: no file; -1: unusable (err), nothing changed. */
int pk_homog_ckpt_load(const char *path, const char *digest, pk_homog_ckpt *c, pk_homog_state *com,
                       json_t **rec, char *err, size_t errlen);

#endif
