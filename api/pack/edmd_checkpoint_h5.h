/* edmd_checkpoint_h5.h — an EDMD snapshot (core/edmd/edmd_checkpoint.h) as an
 * HDF5 file in the job directory, written atomically (temp file, fsync,
 * rename: api/results/h5_result.c), read back to resume.
 *
 *   /observables/checkpoint/digest      the job's digest (inputs + version)
 *   /observables/checkpoint/n, dim      grains, dimension
 *   /observables/checkpoint/kin         [n·8] p[3], a, v[3], g (engine order)
 *   /observables/checkpoint/perm        [n] engine index -> grain
 *   /observables/checkpoint/scalars     [PK_EDMD_SNAP_NSCAL]
 *   /observables/checkpoint/counters    [PK_EDMD_SNAP_NCNT]
 *   /observables/checkpoint/history/{events,time,phi,reduced_pressure} */
#ifndef PK_EDMD_CHECKPOINT_H5_H
#define PK_EDMD_CHECKPOINT_H5_H

#include <stddef.h>

#include "core/edmd/edmd_checkpoint.h"

/* 0, or -1 with err (errno's text: e.g. no space left on device). */
int pk_edmd_ckpt_save(const char *path, const char *digest, const pk_edmd_snapshot *s, char *err,
                      size_t errlen);

/* 0: loaded into s (allocated here; pk_edmd_snapshot_free); 1: no file;
 * -1: unreadable or another job's (digest differs), err says which. */
int pk_edmd_ckpt_load(const char *path, const char *digest, pk_edmd_snapshot *s, char *err,
                      size_t errlen);

#endif
