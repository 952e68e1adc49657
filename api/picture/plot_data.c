/* plot_data.c — series read from a result file for the plots (contract in
 * plot_data.h). */
#include "plot_data.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static H5E_auto2_t saved_func;
static void *saved_data;

hid_t pk_plot_file_open(const char *path)
{
    H5Eget_auto2(H5E_DEFAULT, &saved_func, &saved_data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* an absent series is an answer, not an error */
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        H5Eset_auto2(H5E_DEFAULT, saved_func, saved_data);
    return f;
}

void pk_plot_file_close(hid_t f)
{
    H5Fclose(f);
    H5Eset_auto2(H5E_DEFAULT, saved_func, saved_data);
}

/* The dataset at path, or at path/value (an H5MD time-dependent element). */
static hid_t open_series(hid_t f, const char *path)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d >= 0)
        return d;
    char value[512];
    snprintf(value, sizeof value, "%s/value", path);
    return H5Dopen2(f, value, H5P_DEFAULT);
}

/* Every element of d as doubles, with its shape (rank ≤ 3). */
static double *read_all(hid_t d, int *rank, hsize_t dims[3])
{
    hid_t s = H5Dget_space(d);
    *rank = H5Sget_simple_extent_ndims(s);
    double *v = NULL;
    if (*rank >= 1 && *rank <= 3) {
        H5Sget_simple_extent_dims(s, dims, NULL);
        hsize_t count = 1;
        for (int i = 0; i < *rank; i++)
            count *= dims[i];
        v = count ? malloc(count * sizeof *v) : NULL;
        if (v && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0) {
            free(v);
            v = NULL;
        }
    }
    H5Sclose(s);
    return v;
}

double *pk_plot_series(hid_t f, const char *path, size_t *n)
{
    *n = 0;
    hid_t d = open_series(f, path);
    if (d < 0)
        return NULL;
    int rank;
    hsize_t dims[3];
    double *v = read_all(d, &rank, dims);
    H5Dclose(d);
    if (v && rank != 1) {
        free(v);
        return NULL;
    }
    if (v)
        *n = dims[0];
    return v;
}

double *pk_plot_tensor(hid_t f, const char *path, int a, int b, size_t *n)
{
    char comp[512];
    snprintf(comp, sizeof comp, "%s/%d%d", path, a + 1, b + 1);
    double *v = pk_plot_series(f, comp, n);
    if (v)
        return v;
    hid_t d = open_series(f, path);
    if (d < 0)
        return NULL;
    int rank;
    hsize_t dims[3];
    double *all = read_all(d, &rank, dims);
    H5Dclose(d);
    if (!all || rank != 3 || (hsize_t)a >= dims[1] || (hsize_t)b >= dims[2]) {
        free(all);
        return NULL;
    }
    for (hsize_t k = 0; k < dims[0]; k++)
        all[k] = all[(k * dims[1] + a) * dims[2] + b];
    *n = dims[0];
    return all;
}

/* The string held by an attribute (attr = 1) or a scalar dataset of type t,
 * fixed or variable length, malloc'd; NULL for any other type. */
static char *read_string(hid_t obj, hid_t t, int attr)
{
    if (H5Tget_class(t) != H5T_STRING)
        return NULL;
    if (H5Tis_variable_str(t) > 0) {
        char *s = NULL, *copy = NULL;
        hid_t mt = H5Tcopy(H5T_C_S1);
        H5Tset_size(mt, H5T_VARIABLE);
        herr_t rc =
            attr ? H5Aread(obj, mt, &s) : H5Dread(obj, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, &s);
        if (rc >= 0 && s) {
            copy = strdup(s);
            H5free_memory(s);
        }
        H5Tclose(mt);
        return copy;
    }
    size_t len = H5Tget_size(t);
    char *buf = calloc(len + 1, 1);
    herr_t rc = !buf ? -1
        : attr       ? H5Aread(obj, t, buf)
                     : H5Dread(obj, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
    if (rc < 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

static void copy_out(char *s, char *out, size_t n)
{
    snprintf(out, n, "%s", s ? s : "");
    free(s);
}

void pk_plot_unit(hid_t f, const char *path, char *out, size_t n)
{
    out[0] = 0;
    hid_t d = open_series(f, path);
    if (d < 0)
        return;
    if (H5Aexists(d, "unit") > 0) {
        hid_t a = H5Aopen(d, "unit", H5P_DEFAULT), t = H5Aget_type(a);
        copy_out(read_string(a, t, 1), out, n);
        H5Tclose(t);
        H5Aclose(a);
    }
    H5Dclose(d);
}

char *pk_plot_text(hid_t f, const char *path)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0)
        return NULL;
    hid_t t = H5Dget_type(d);
    char *s = read_string(d, t, 0);
    H5Tclose(t);
    H5Dclose(d);
    return s;
}

void pk_plot_string(hid_t f, const char *path, char *out, size_t n)
{
    copy_out(pk_plot_text(f, path), out, n);
}

double pk_plot_scalar(hid_t f, const char *path)
{
    double v = NAN;
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0)
        return v;
    hid_t t = H5Dget_type(d), s = H5Dget_space(d);
    if ((H5Tget_class(t) == H5T_FLOAT || H5Tget_class(t) == H5T_INTEGER) &&
        H5Sget_simple_extent_npoints(s) == 1 &&
        H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) < 0)
        v = NAN;
    H5Sclose(s);
    H5Tclose(t);
    H5Dclose(d);
    return v;
}
