/* homog_frames.h — the deformed grains of every recorded load step, kept
 * for the result file as H5MD time-dependent elements under /particles/rve
 * (docs/result-format.md) so a viewer (the XDMF sidecar's temporal
 * collection) can play the load path: positions [steps][n][dim] and the
 * contact force carried by each grain [steps][n], with a per-step view of
 * each (an HDF5 virtual dataset) that the sidecar reads.
 *
 * Rule: the frames are kept when the load path has at most
 * PK_HOMOG_FRAMES_MAX_STEPS steps and steps·n <= PK_HOMOG_FRAMES_MAX
 * grain-steps (at most 24 MiB of positions in 3D); a larger run keeps none
 * and its sidecar shows the reference packing only. */
#ifndef PK_HOMOG_FRAMES_H
#define PK_HOMOG_FRAMES_H

#include <stddef.h>
#include <stdint.h>

#include "api/results/h5_result.h"
#include "api/results/h5_units.h"
#include "core/homog/homog_bc.h"
#include "core/homog/homog_rve.h"

#define PK_HOMOG_FRAMES_MAX ((size_t)1000000)
#define PK_HOMOG_FRAMES_MAX_STEPS ((size_t)1000) /* two XDMF grids per step in the sidecar */

typedef struct pk_homog_frames {
    int dim, keep;
    size_t n, count, cap;
    int64_t *step; /* [count] index of the load step */
    double *time;  /* [count] load fraction (step + 1) / steps */
    double *x;     /* [count][n][dim] centres */
    double *force; /* [count][n] Σ_j |f_n,ij| over the grain's contacts */
} pk_homog_frames;

/* Empty frames for an RVE and a load path of nstep steps (keep decided by
 * the rule above). */
void pk_homog_frames_init(pk_homog_frames *fr, const pk_homog_rve *rve, size_t nstep);
/* Record the committed state s of load step k of nstep.  0 / -1 (memory). */
int pk_homog_frames_add(pk_homog_frames *fr, const pk_homog_rve *rve, const pk_homog_opts *o,
                        const pk_homog_state *s, size_t k, size_t nstep);
/* Write /particles/rve: box, radius, grain and id always (the particles
 * group of /connectivity/contacts), position and contact_force when frames
 * were kept; units of u. */
int pk_homog_frames_write(pk_h5 *h, const pk_homog_frames *fr, const pk_homog_rve *rve,
                          const pk_units *u);
void pk_homog_frames_free(pk_homog_frames *fr);

#endif
