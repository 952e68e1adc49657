/* checkpoint_h5.c — checkpoint files read back (api/results/checkpoint_h5.h). */
#include "checkpoint_h5.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define ROOT "/observables/checkpoint/"

static hid_t open_ds(hid_t f, const char *name)
{
    char path[160];
    if (snprintf(path, sizeof path, ROOT "%s", name) >= (int)sizeof path)
        return -1;
    return H5Dopen2(f, path, H5P_DEFAULT); /* (errors are silenced: -1 when absent) */
}

long long pk_ckpt_len(hid_t f, const char *name)
{
    hid_t d = open_ds(f, name);
    if (d < 0)
        return -1;
    hid_t sp = H5Dget_space(d);
    hssize_t n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(d);
    return (long long)n;
}

int pk_ckpt_read(hid_t f, const char *name, hid_t t, void *buf, size_t want)
{
    if (pk_ckpt_len(f, name) != (long long)want)
        return -1;
    if (want == 0)
        return 0;
    hid_t d = open_ds(f, name);
    int rc = d >= 0 && H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0 ? 0 : -1;
    if (d >= 0)
        H5Dclose(d);
    return rc;
}

char *pk_ckpt_read_string(hid_t f, const char *name)
{
    hid_t d = open_ds(f, name);
    if (d < 0)
        return NULL;
    hid_t t = H5Dget_type(d);
    size_t len =
        t >= 0 && H5Tget_class(t) == H5T_STRING && !H5Tis_variable_str(t) ? H5Tget_size(t) : 0;
    char *s = len ? malloc(len + 1) : NULL;
    if (s && H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, s) >= 0) {
        s[len] = 0;
    } else {
        free(s);
        s = NULL;
    }
    if (t >= 0)
        H5Tclose(t);
    H5Dclose(d);
    return s;
}

hid_t pk_ckpt_open(const char *path, const char *digest, int *absent, char *err, size_t errlen)
{
    *absent = access(path, F_OK) != 0;
    if (*absent)
        return -1;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) {
        snprintf(err, errlen, "checkpoint %s is not readable HDF5", path);
        return -1;
    }
    char *dg = pk_ckpt_read_string(f, "digest");
    if (!dg || strcmp(dg, digest) != 0) {
        snprintf(err, errlen,
                 dg ? "checkpoint %s belongs to another job or packd version"
                    : "checkpoint %s is incomplete",
                 path);
        free(dg);
        H5Fclose(f);
        return -1;
    }
    free(dg);
    return f;
}
