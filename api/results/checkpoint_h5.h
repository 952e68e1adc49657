/* checkpoint_h5.h — reading back the checkpoint files of long runs (EDMD
 * snapshots, homogenization load steps).  A checkpoint is a packd HDF5 file
 * (written with api/results/h5_result.h: temp file, fsync, rename) whose datasets
 * sit under /observables/checkpoint/, with the job's digest in
 * /observables/checkpoint/digest: a file of another job is never used. */
#ifndef PK_CHECKPOINT_H5_H
#define PK_CHECKPOINT_H5_H

#include <hdf5.h>
#include <stddef.h>

/* Open path and check its digest: the file (H5Fclose it), or -1 with err;
 * *absent = 1 when there is no file at all (not an error: start anew). */
hid_t pk_ckpt_open(const char *path, const char *digest, int *absent, char *err, size_t errlen);

/* Elements of dataset name (under /observables/checkpoint/), -1 if none. */
long long pk_ckpt_len(hid_t f, const char *name);
/* Exactly want elements of type t (a native type) into buf: 0 or -1. */
int pk_ckpt_read(hid_t f, const char *name, hid_t t, void *buf, size_t want);
/* A string dataset, malloc'd (free it); NULL if absent. */
char *pk_ckpt_read_string(hid_t f, const char *name);

#endif
