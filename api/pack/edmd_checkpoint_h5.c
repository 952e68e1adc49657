/* edmd_checkpoint_h5.c — EDMD snapshots in HDF5 (api/pack/edmd_checkpoint_h5.h). */
#include "edmd_checkpoint_h5.h"

#include <hdf5.h>
#include <stdio.h>
#include <string.h>

#include "api/results/checkpoint_h5.h"
#include "api/results/h5_result.h"

#define G "checkpoint/"

static const char *hist_names[4] = {"events", "time", "phi", "reduced_pressure"};

int pk_edmd_ckpt_save(const char *path, const char *digest, const pk_edmd_snapshot *s, char *err,
                      size_t errlen)
{
    pk_h5 *h = pk_h5_create(path, NULL, err, errlen);
    if (!h)
        return -1;
    int rc = pk_h5_obs_string(h, G "digest", digest);
    rc |= pk_h5_obs_int(h, G "n", (int64_t)s->n);
    rc |= pk_h5_obs_int(h, G "dim", s->dim);
    rc |= pk_h5_obs_doubles(h, G "kin", s->kin, s->n * PK_EDMD_SNAP_KIN, NULL);
    rc |= pk_h5_obs_ints(h, G "perm", s->perm, s->n);
    rc |= pk_h5_obs_doubles(h, G "scalars", s->scal, PK_EDMD_SNAP_NSCAL, NULL);
    rc |= pk_h5_obs_ints(h, G "counters", s->cnt, PK_EDMD_SNAP_NCNT);
    for (int k = 0; k < 4; k++) {
        char name[64];
        snprintf(name, sizeof name, G "history/%s", hist_names[k]);
        rc |= pk_h5_obs_doubles(h, name, s->hist[k], s->nhist, NULL);
    }
    if (rc) {
        snprintf(err, errlen, "cannot build the checkpoint %s", path);
        pk_h5_abort(h);
        return -1;
    }
    return pk_h5_commit(h, err, errlen);
}

int pk_edmd_ckpt_load(const char *path, const char *digest, pk_edmd_snapshot *s, char *err,
                      size_t errlen)
{
    memset(s, 0, sizeof *s);
    int absent;
    hid_t f = pk_ckpt_open(path, digest, &absent, err, errlen);
    if (f < 0)
        return absent ? 1 : -1;
    int64_t n = -1, dim = 0;
    long long nh = pk_ckpt_len(f, "history/events");
    int rc = -1;
    if (pk_ckpt_read(f, "n", H5T_NATIVE_INT64, &n, 1) != 0 ||
        pk_ckpt_read(f, "dim", H5T_NATIVE_INT64, &dim, 1) != 0 || n < 1 || (dim != 2 && dim != 3) ||
        nh < 0 || nh > PK_EDMD_HIST_MAX) {
        snprintf(err, errlen, "checkpoint %s is incomplete", path);
        goto out;
    }
    if (pk_edmd_snapshot_alloc(s, (size_t)n, (int)dim) != 0) {
        snprintf(err, errlen, "out of memory for the checkpoint of %lld grains", (long long)n);
        goto out;
    }
    s->nhist = (size_t)nh;
    int bad = pk_ckpt_read(f, "kin", H5T_NATIVE_DOUBLE, s->kin, s->n * PK_EDMD_SNAP_KIN);
    bad |= pk_ckpt_read(f, "perm", H5T_NATIVE_INT64, s->perm, s->n);
    bad |= pk_ckpt_read(f, "scalars", H5T_NATIVE_DOUBLE, s->scal, PK_EDMD_SNAP_NSCAL);
    bad |= pk_ckpt_read(f, "counters", H5T_NATIVE_INT64, s->cnt, PK_EDMD_SNAP_NCNT);
    for (int k = 0; k < 4 && !bad; k++) {
        char name[64];
        snprintf(name, sizeof name, "history/%s", hist_names[k]);
        bad |= pk_ckpt_read(f, name, H5T_NATIVE_DOUBLE, s->hist[k], s->nhist);
    }
    if (bad) {
        snprintf(err, errlen, "checkpoint %s is incomplete", path);
        pk_edmd_snapshot_free(s);
        goto out;
    }
    rc = 0;
out:
    H5Fclose(f);
    return rc;
}
