/* edmd_checkpoint_h5.c — EDMD snapshots in HDF5 (api/edmd_checkpoint_h5.h). */
#include "edmd_checkpoint_h5.h"

#include <errno.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5_result.h"

#define G "checkpoint/"
#define ROOT "/observables/checkpoint/"

static const char *hist_names[4] = {"events", "time", "phi", "reduced_pressure"};

int pk_edmd_ckpt_save(const char *path, const char *digest, const pk_edmd_snapshot *s, char *err,
                      size_t errlen)
{
    pk_h5 *h = pk_h5_create(path, err, errlen);
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

/* A 1-d (or scalar: want = 1) dataset of exactly `want` elements of type t. */
static int read_exact(hid_t f, const char *name, hid_t t, void *buf, size_t want)
{
    char path[128];
    snprintf(path, sizeof path, ROOT "%s", name);
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0)
        return -1;
    hid_t sp = H5Dget_space(d);
    hssize_t n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    int rc = n == (hssize_t)want && (want == 0 || H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0)
                 ? 0
                 : -1;
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(d);
    return rc;
}

static int read_string(hid_t f, const char *name, char *out, size_t n)
{
    char path[128];
    snprintf(path, sizeof path, ROOT "%s", name);
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0)
        return -1;
    hid_t t = H5Dget_type(d);
    size_t len = t >= 0 ? H5Tget_size(t) : 0;
    int rc = -1;
    if (len > 0 && len < n && !H5Tis_variable_str(t) && H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0) {
        out[len] = 0;
        rc = 0;
    }
    if (t >= 0)
        H5Tclose(t);
    H5Dclose(d);
    return rc;
}

int pk_edmd_ckpt_load(const char *path, const char *digest, pk_edmd_snapshot *s, char *err,
                      size_t errlen)
{
    memset(s, 0, sizeof *s);
    if (access(path, F_OK) != 0)
        return 1;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) {
        snprintf(err, errlen, "checkpoint %s is not readable HDF5", path);
        return -1;
    }
    char dg[256];
    int64_t n = -1, dim = 0;
    int rc = -1;
    if (read_string(f, "digest", dg, sizeof dg) != 0 || read_exact(f, "n", H5T_NATIVE_INT64, &n, 1) != 0 ||
        read_exact(f, "dim", H5T_NATIVE_INT64, &dim, 1) != 0 || n < 1 || (dim != 2 && dim != 3)) {
        snprintf(err, errlen, "checkpoint %s is incomplete", path);
        goto out;
    }
    if (strcmp(dg, digest) != 0) {
        snprintf(err, errlen, "checkpoint %s belongs to another job or packd version", path);
        goto out;
    }
    if (pk_edmd_snapshot_alloc(s, (size_t)n, (int)dim) != 0) {
        snprintf(err, errlen, "out of memory for the checkpoint of %lld grains", (long long)n);
        goto out;
    }
    hid_t ds = H5Dopen2(f, ROOT "history/events", H5P_DEFAULT);
    hid_t sp = ds >= 0 ? H5Dget_space(ds) : -1;
    hssize_t nh = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    s->nhist = nh >= 0 && nh <= PK_EDMD_HIST_MAX ? (size_t)nh : 0;
    int bad = nh < 0 || nh > PK_EDMD_HIST_MAX;
    bad |= read_exact(f, "kin", H5T_NATIVE_DOUBLE, s->kin, s->n * PK_EDMD_SNAP_KIN);
    bad |= read_exact(f, "perm", H5T_NATIVE_INT64, s->perm, s->n);
    bad |= read_exact(f, "scalars", H5T_NATIVE_DOUBLE, s->scal, PK_EDMD_SNAP_NSCAL);
    bad |= read_exact(f, "counters", H5T_NATIVE_INT64, s->cnt, PK_EDMD_SNAP_NCNT);
    for (int k = 0; k < 4 && !bad; k++) {
        char name[64];
        snprintf(name, sizeof name, "history/%s", hist_names[k]);
        bad |= read_exact(f, name, H5T_NATIVE_DOUBLE, s->hist[k], s->nhist);
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
