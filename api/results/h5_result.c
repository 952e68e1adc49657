/* h5_result.c — the H5MD 1.1 result file writer (docs/result-format.md).
 * Contract: api/results/h5_result.h. */
#include "h5_result.h"
#include "result_digest.h"

#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api/inputs/input_open.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

struct pk_h5 {
    hid_t file;
    hid_t obs;  /* /observables */
    hid_t lcpl; /* link creation: intermediate groups */
    int fd;     /* the temporary file, written at commit */
    char *path, *tmp;
    int failed; /* sticky: a writer failed since pk_h5_create (pk_h5_commit refuses) */
};

/* A writer's status, remembered in h: the callers write on without summing
 * return codes, pk_h5_commit reports the first failure's consequence. */
static int sticky(pk_h5 *h, int rc)
{
    if (rc != 0)
        h->failed = 1;
    return rc;
}

static void quiet_hdf5(void)
{
    /* Errors are reported through return codes and our own messages. */
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static hid_t string_type(size_t len)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, len ? len : 1);
    H5Tset_strpad(t, H5T_STR_NULLTERM);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}

/* A scalar fixed-length string attribute in character set cset. */
static int attr_text(hid_t obj, const char *name, const char *v, H5T_cset_t cset)
{
    hid_t t = string_type(strlen(v) + 1), s = H5Screate(H5S_SCALAR);
    H5Tset_cset(t, cset);
    hid_t a = H5Acreate2(obj, name, t, s, H5P_DEFAULT, H5P_DEFAULT);
    herr_t rc = a < 0 ? -1 : H5Awrite(a, t, v);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(s);
    H5Tclose(t);
    return rc < 0 ? -1 : 0;
}

static int attr_string(hid_t obj, const char *name, const char *v)
{
    return attr_text(obj, name, v, H5T_CSET_UTF8);
}

/* An H5MD unit attribute (units module 1.0: scalar, fixed-length, ASCII). */
static int attr_unit(hid_t obj, const char *v) { return attr_text(obj, "unit", v, H5T_CSET_ASCII); }

static int attr_ints(hid_t obj, const char *name, const int *v, hsize_t n, int scalar)
{
    hid_t s = scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, NULL);
    hid_t a = H5Acreate2(obj, name, H5T_NATIVE_INT, s, H5P_DEFAULT, H5P_DEFAULT);
    herr_t rc = a < 0 ? -1 : H5Awrite(a, H5T_NATIVE_INT, v);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(s);
    return rc < 0 ? -1 : 0;
}

static int attr_u64(hid_t obj, const char *name, uint64_t v)
{
    hid_t s = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, H5T_NATIVE_UINT64, s, H5P_DEFAULT, H5P_DEFAULT);
    herr_t rc = a < 0 ? -1 : H5Awrite(a, H5T_NATIVE_UINT64, &v);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(s);
    return rc < 0 ? -1 : 0;
}

/* Dataset creation without timestamps, so equal inputs give equal bytes. */
static hid_t dcpl_untimed(void)
{
    hid_t p = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_obj_track_times(p, 0);
    return p;
}

static hid_t gcpl_untimed(void)
{
    hid_t p = H5Pcreate(H5P_GROUP_CREATE);
    H5Pset_obj_track_times(p, 0);
    return p;
}

static hid_t make_group(hid_t parent, const char *name, hid_t lcpl)
{
    hid_t g = gcpl_untimed();
    hid_t id = H5Gcreate2(parent, name, lcpl, g, H5P_DEFAULT);
    H5Pclose(g);
    return id;
}

/* Write an n-d dataset of `type` at parent/name; optional unit attribute. */
static int write_dataset(hid_t parent, hid_t lcpl, const char *name, hid_t type, int rank,
                         const hsize_t *dims, const void *data, const char *unit)
{
    hid_t s = rank == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(rank, dims, NULL);
    hid_t p = dcpl_untimed();
    hid_t d = H5Dcreate2(parent, name, type, s, lcpl, p, H5P_DEFAULT);
    herr_t rc = -1;
    if (d >= 0) {
        hsize_t total = 1;
        for (int k = 0; k < rank; k++)
            total *= dims[k];
        rc = total ? H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) : 0;
        if (rc >= 0 && unit)
            rc = attr_unit(d, unit);
        H5Dclose(d);
    }
    H5Pclose(p);
    H5Sclose(s);
    return rc < 0 ? -1 : 0;
}

pk_h5 *pk_h5_create(const char *path, const char *author, char *err, size_t errlen)
{
    quiet_hdf5();
    pk_h5 *h = calloc(1, sizeof *h);
    if (!h) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    size_t n = strlen(path) + 32;
    h->path = strdup(path);
    h->tmp = malloc(n);
    if (!h->path || !h->tmp) {
        free(h->path);
        free(h->tmp);
        free(h);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    snprintf(h->tmp, n, "%s.tmp.%ld", path, (long)getpid());
    unlink(h->tmp);
    /* The file is built in memory (HDF5's core driver, no backing store) and
     * written out by pk_h5_commit with plain write(2): a full disk is then an
     * errno of ours, and HDF5 never holds a file it failed to flush (its exit
     * handler would close it again and crash).  The temporary file is created
     * now so a directory that cannot take it fails before the work. */
    h->fd = open(h->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, PK_RESULT_FILE_MODE);
    if (h->fd < 0) {
        snprintf(err, errlen, "cannot create %s: %s", h->tmp, strerror(errno));
        free(h->path);
        free(h->tmp);
        free(h);
        return NULL;
    }
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE), fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_fapl_core(fapl, (size_t)1 << 20, 0);
    h->file = H5Fcreate(h->tmp, H5F_ACC_TRUNC, fcpl, fapl);
    H5Pclose(fcpl);
    H5Pclose(fapl);
    if (h->file < 0) {
        snprintf(err, errlen, "cannot create %s in memory", h->tmp);
        close(h->fd);
        unlink(h->tmp);
        free(h->path);
        free(h->tmp);
        free(h);
        return NULL;
    }
    h->lcpl = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(h->lcpl, 1);
    H5Pset_char_encoding(h->lcpl, H5T_CSET_UTF8);

    /* /h5md: version, author, creator (H5MD 1.1 §"H5MD metadata"). */
    hid_t md = make_group(h->file, "h5md", H5P_DEFAULT);
    int ver[2] = {1, 1};
    attr_ints(md, "version", ver, 2, 0);
    hid_t au = make_group(md, "author", H5P_DEFAULT);
    /* the person responsible; the name is mandatory, so an unknown one says so */
    attr_string(au, "name", author && *author ? author : PK_H5_AUTHOR_UNKNOWN);
    H5Gclose(au);
    /* the units module: every dimensional dataset carries a `unit` string of
     * SI symbols ("mm", "N mm-2"); H5MD units module 1.0 */
    hid_t un = make_group(md, "modules/units", h->lcpl);
    int uver[2] = {1, 0};
    attr_ints(un, "version", uver, 2, 0);
    {
        hid_t t = string_type(3), s = H5Screate(H5S_SCALAR);
        H5Tset_cset(t, H5T_CSET_ASCII);
        hid_t a = H5Acreate2(un, "system", t, s, H5P_DEFAULT, H5P_DEFAULT);
        if (a >= 0) {
            H5Awrite(a, t, "SI");
            H5Aclose(a);
        }
        H5Sclose(s);
        H5Tclose(t);
    }
    H5Gclose(un);
    hid_t cr = make_group(md, "creator", H5P_DEFAULT);
    attr_string(cr, "name", "packd");
    attr_string(cr, "version", PACKD_VERSION);
    H5Gclose(cr);
    H5Gclose(md);
    h->obs = make_group(h->file, "observables", H5P_DEFAULT);
    if (h->obs < 0) {
        snprintf(err, errlen, "cannot write %s", h->tmp);
        pk_h5_abort(h);
        return NULL;
    }
    return h;
}

int pk_h5_write_particles(pk_h5 *h, const pk_box *b, const pk_particles *p, const char *unit)
{
    const int dim = b->dim;
    hid_t grains = make_group(h->file, "particles/grains", h->lcpl);
    if (grains < 0)
        return sticky(h, -1);
    int rc = 0;
    hid_t box = make_group(grains, "box", H5P_DEFAULT);
    rc |= attr_ints(box, "dimension", &dim, 1, 1);
    {
        /* boundary: fixed-length string array, "periodic" or "none" per axis */
        char names[PK_MAXDIM][9];
        for (int k = 0; k < dim; k++)
            snprintf(names[k], sizeof names[k], "%s", b->periodic[k] ? "periodic" : "none");
        hid_t t = string_type(9);
        hsize_t n = (hsize_t)dim;
        hid_t s = H5Screate_simple(1, &n, NULL);
        hid_t a = H5Acreate2(box, "boundary", t, s, H5P_DEFAULT, H5P_DEFAULT);
        rc |= (a < 0 || H5Awrite(a, t, names) < 0) ? -1 : 0;
        if (a >= 0)
            H5Aclose(a);
        H5Sclose(s);
        H5Tclose(t);
    }
    hsize_t nd = (hsize_t)dim;
    rc |= write_dataset(box, H5P_DEFAULT, "edges", H5T_NATIVE_DOUBLE, 1, &nd, b->L, unit);
    H5Gclose(box);

    size_t n = p->n;
    double *pos = malloc((n ? n : 1) * (size_t)dim * sizeof *pos);
    if (!pos) {
        H5Gclose(grains);
        return sticky(h, -1);
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < dim; k++)
            pos[i * (size_t)dim + (size_t)k] = p->x[3 * i + (size_t)k];
    hsize_t d2[2] = {(hsize_t)n, (hsize_t)dim};
    rc |= write_dataset(grains, H5P_DEFAULT, "position", H5T_NATIVE_DOUBLE, 2, d2, pos, unit);
    free(pos);
    hsize_t d1 = (hsize_t)n;
    rc |= write_dataset(grains, H5P_DEFAULT, "radius", H5T_NATIVE_DOUBLE, 1, &d1, p->r, unit);
    rc |= write_dataset(grains, H5P_DEFAULT, "species", H5T_NATIVE_INT32, 1, &d1, p->species, NULL);
    /* H5MD's id element (0..N-1): also the Polyvertex connectivity of the XDMF sidecar */
    int64_t *id = malloc((n ? n : 1) * sizeof *id);
    if (!id) {
        H5Gclose(grains);
        return sticky(h, -1);
    }
    for (size_t i = 0; i < n; i++)
        id[i] = (int64_t)i;
    rc |= write_dataset(grains, H5P_DEFAULT, "id", H5T_NATIVE_INT64, 1, &d1, id, NULL);
    free(id);
    H5Gclose(grains);
    return sticky(h, rc ? -1 : 0);
}

int pk_h5_write_parameters(pk_h5 *h, const char *process, const char *job_json, uint64_t seed)
{
    hid_t g = make_group(h->file, "parameters", H5P_DEFAULT);
    if (g < 0)
        return sticky(h, -1);
    int rc = attr_string(g, "process", process);
    rc |= attr_string(g, "packd_version", PACKD_VERSION);
    rc |= attr_u64(g, "seed", seed);
    /* The job as given, as a dataset: attributes are limited to 64 KiB and a
     * job may carry an inline mesh. */
    hid_t t = string_type(strlen(job_json) + 1);
    rc |= write_dataset(g, H5P_DEFAULT, "job", t, 0, NULL, job_json, NULL);
    H5Tclose(t);
    H5Gclose(g);
    return sticky(h, rc ? -1 : 0);
}

int pk_h5_obs_double(pk_h5 *h, const char *name, double v, const char *unit)
{
    return sticky(h, write_dataset(h->obs, h->lcpl, name, H5T_NATIVE_DOUBLE, 0, NULL, &v, unit));
}

int pk_h5_obs_int(pk_h5 *h, const char *name, int64_t v)
{
    return sticky(h, write_dataset(h->obs, h->lcpl, name, H5T_NATIVE_INT64, 0, NULL, &v, NULL));
}

int pk_h5_obs_string(pk_h5 *h, const char *name, const char *v)
{
    hid_t t = string_type(strlen(v) + 1);
    int rc = write_dataset(h->obs, h->lcpl, name, t, 0, NULL, v, NULL);
    H5Tclose(t);
    return sticky(h, rc);
}

int pk_h5_obs_doubles(pk_h5 *h, const char *name, const double *v, size_t n, const char *unit)
{
    hsize_t d = (hsize_t)n;
    return sticky(h, write_dataset(h->obs, h->lcpl, name, H5T_NATIVE_DOUBLE, 1, &d, v, unit));
}

int pk_h5_obs_ints(pk_h5 *h, const char *name, const int64_t *v, size_t n)
{
    hsize_t d = (hsize_t)n;
    return sticky(h, write_dataset(h->obs, h->lcpl, name, H5T_NATIVE_INT64, 1, &d, v, NULL));
}

int pk_h5_write_array(pk_h5 *h, const char *path, pk_h5_type type, int rank, const size_t *dims,
                      const void *data, const char *unit)
{
    hsize_t d[5];
    if (rank < 0 || rank > 5)
        return sticky(h, -1);
    for (int k = 0; k < rank; k++)
        d[k] = (hsize_t)dims[k];
    hid_t t = type == PK_H5_F64 ? H5T_NATIVE_DOUBLE
        : type == PK_H5_I64     ? H5T_NATIVE_INT64
                                : H5T_NATIVE_INT32;
    return sticky(h, write_dataset(h->file, h->lcpl, path, t, rank, d, data, unit));
}

int pk_h5_link(pk_h5 *h, const char *existing, const char *path)
{
    return sticky(
        h, H5Lcreate_hard(h->file, existing, h->file, path, h->lcpl, H5P_DEFAULT) < 0 ? -1 : 0);
}

int pk_h5_obs_json_units(pk_h5 *h, const char *prefix, json_t *obj, pk_h5_unit_fn unit_of,
                         const void *ctx)
{
    const char *key;
    json_t *v;
    int rc = 0;
    json_object_foreach (obj, key, v) {
        char name[256];
        snprintf(name, sizeof name, "%s/%s", prefix, key);
        const char *unit = unit_of ? unit_of(name, ctx) : NULL;
        if (json_is_integer(v))
            rc |= unit ? pk_h5_obs_double(h, name, (double)json_integer_value(v), unit)
                       : pk_h5_obs_int(h, name, (int64_t)json_integer_value(v));
        else if (json_is_real(v))
            rc |= pk_h5_obs_double(h, name, json_real_value(v), unit);
        else if (json_is_boolean(v))
            rc |= pk_h5_obs_int(h, name, json_is_true(v));
        else if (json_is_string(v))
            rc |= pk_h5_obs_string(h, name, json_string_value(v));
        else if (json_is_object(v))
            rc |= pk_h5_obs_json_units(h, name, v, unit_of, ctx);
        else if (json_is_array(v)) {
            size_t n = json_array_size(v), i;
            int all_int = 1, all_num = 1;
            json_t *e;
            json_array_foreach (v, i, e) {
                all_int &= json_is_integer(e);
                all_num &= json_is_number(e);
            }
            if (!all_num)
                continue;
            if (all_int) {
                int64_t *a = malloc((n ? n : 1) * sizeof *a);
                if (!a)
                    return sticky(h, -1);
                json_array_foreach (v, i, e)
                    a[i] = (int64_t)json_integer_value(e);
                rc |= pk_h5_obs_ints(h, name, a, n);
                free(a);
            } else {
                double *a = malloc((n ? n : 1) * sizeof *a);
                if (!a)
                    return sticky(h, -1);
                json_array_foreach (v, i, e)
                    a[i] = json_number_value(e);
                rc |= pk_h5_obs_doubles(h, name, a, n, unit);
                free(a);
            }
        }
    }
    return sticky(h, rc ? -1 : 0);
}

int pk_h5_obs_json(pk_h5 *h, const char *prefix, json_t *obj)
{
    return pk_h5_obs_json_units(h, prefix, obj, NULL, NULL);
}

int pk_h5_time_element(pk_h5 *h, const char *path, const char *clock, const int64_t *step,
                       const double *time, const char *time_unit, pk_h5_type type, int rank,
                       const size_t *dims, const void *value, const char *unit)
{
    char p[512], c[512];
    int rc = 0;
    snprintf(p, sizeof p, "%s/step", path);
    if (clock) {
        snprintf(c, sizeof c, "%s/step", clock);
        rc |= pk_h5_link(h, c, p);
        snprintf(c, sizeof c, "%s/time", clock);
        snprintf(p, sizeof p, "%s/time", path);
        rc |= pk_h5_link(h, c, p);
    } else {
        rc |= pk_h5_write_array(h, p, PK_H5_I64, 1, dims, step, NULL);
        snprintf(p, sizeof p, "%s/time", path);
        rc |= pk_h5_write_array(h, p, PK_H5_F64, 1, dims, time,
                                time_unit ? time_unit : PK_H5_UNIT_NUMBER);
    }
    snprintf(p, sizeof p, "%s/value", path);
    rc |= pk_h5_write_array(h, p, type, rank, dims, value, unit);
    return sticky(h, rc ? -1 : 0);
}

int pk_h5_obs_history(pk_h5 *h, const char *prefix, json_t *hist, const char *step_key,
                      const char *time_key)
{
    json_t *st = json_object_get(hist, step_key), *tm = json_object_get(hist, time_key);
    size_t S = json_array_size(st);
    if (json_array_size(tm) != S)
        return sticky(h, -1);
    int64_t *step = malloc((S ? S : 1) * sizeof *step);
    double *time = malloc((S ? S : 1) * sizeof *time), *v = malloc((S ? S : 1) * sizeof *v);
    int rc = step && time && v ? 0 : -1;
    for (size_t k = 0; rc == 0 && k < S; k++) {
        step[k] = (int64_t)json_number_value(json_array_get(st, k));
        time[k] = json_number_value(json_array_get(tm, k));
    }
    char clock[256] = "";
    const char *key;
    json_t *arr;
    json_object_foreach (hist, key, arr) {
        if (rc || !strcmp(key, step_key) || !strcmp(key, time_key) || !json_is_array(arr) ||
            json_array_size(arr) != S)
            continue;
        char path[256];
        snprintf(path, sizeof path, "/observables/%s/%s", prefix, key);
        for (size_t k = 0; k < S; k++)
            v[k] = json_number_value(json_array_get(arr, k));
        rc |= pk_h5_time_element(h, path, *clock ? clock : NULL, step, time, NULL, PK_H5_F64, 1, &S,
                                 v, NULL);
        if (!*clock)
            snprintf(clock, sizeof clock, "%s", path);
    }
    free(step);
    free(time);
    free(v);
    return sticky(h, rc);
}

int pk_h5_connectivity(pk_h5 *h, const char *path, const int64_t *pairs, size_t n,
                       const char *particles_group)
{
    size_t d[2] = {n, 2};
    if (pk_h5_write_array(h, path, PK_H5_I64, 2, d, pairs, NULL) != 0)
        return sticky(h, -1);
    /* H5MD 1.1 connectivity: the particles group the indices refer to */
    hobj_ref_t ref;
    hid_t ds = H5Dopen2(h->file, path, H5P_DEFAULT), s = H5Screate(H5S_SCALAR);
    int rc = -1;
    if (ds >= 0 && H5Rcreate(&ref, h->file, particles_group, H5R_OBJECT, -1) >= 0) {
        hid_t a = H5Acreate2(ds, "particles_group", H5T_STD_REF_OBJ, s, H5P_DEFAULT, H5P_DEFAULT);
        if (a >= 0) {
            rc = H5Awrite(a, H5T_STD_REF_OBJ, &ref) < 0 ? -1 : 0;
            H5Aclose(a);
        }
    }
    H5Sclose(s);
    if (ds >= 0)
        H5Dclose(ds);
    return sticky(h, rc);
}

static void h5_free(pk_h5 *h)
{
    free(h->path);
    free(h->tmp);
    free(h);
}

static void h5_close_all(pk_h5 *h)
{
    if (h->obs >= 0)
        H5Gclose(h->obs);
    H5Pclose(h->lcpl);
    H5Fclose(h->file);
}

/* All of buf to fd: 0, or -1 with errno. */
static int write_all(int fd, const unsigned char *buf, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, buf, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            if (w == 0)
                errno = EIO;
            return -1;
        }
        buf += w;
        n -= (size_t)w;
    }
    return 0;
}

/* /parameters/result_digest of a result (job and grains written): the
 * content hash of result_digest.h, with the method as its attribute. */
static void write_result_digest(pk_h5 *h)
{
    char hex[65];
    hid_t g;
    H5E_BEGIN_TRY
    {
        g = pk_result_digest_compute(h->file, hex) == 0
            ? H5Gopen2(h->file, "parameters", H5P_DEFAULT)
            : -1;
    }
    H5E_END_TRY
    if (g < 0)
        return;
    hid_t t = string_type(sizeof hex);
    if (write_dataset(g, H5P_DEFAULT, "result_digest", t, 0, NULL, hex, NULL) == 0) {
        hid_t d = H5Dopen2(g, "result_digest", H5P_DEFAULT);
        attr_string(d, "method", PK_RESULT_DIGEST_METHOD);
        H5Dclose(d);
    }
    H5Tclose(t);
    H5Gclose(g);
}

int pk_h5_failed(const pk_h5 *h) { return h->failed; }

int pk_h5_commit(pk_h5 *h, char *err, size_t errlen)
{
    if (h->failed) { /* a half-written file never takes the result's name */
        snprintf(err, errlen, "writing %s failed", h->path);
        pk_h5_abort(h);
        return -1;
    }
    write_result_digest(h);
    unsigned char *img = NULL;
    ssize_t n = H5Fflush(h->file, H5F_SCOPE_GLOBAL) < 0 ? -1 : H5Fget_file_image(h->file, NULL, 0);
    if (n > 0 && (img = malloc((size_t)n)) != NULL &&
        H5Fget_file_image(h->file, img, (size_t)n) != n) {
        free(img);
        img = NULL;
    }
    h5_close_all(h);
    int rc = -1, saved = ENOMEM;
    if (img) {
        rc = write_all(h->fd, img, (size_t)n) != 0 || fsync(h->fd) != 0 ? -1 : 0;
        saved = errno;
    }
    free(img);
    if (close(h->fd) != 0 && rc == 0) {
        rc = -1;
        saved = errno;
    }
    if (rc == 0 && rename(h->tmp, h->path) != 0) {
        rc = -1;
        saved = errno;
    }
    if (rc != 0) {
        snprintf(err, errlen, "cannot write %s: %s", h->path, strerror(saved));
        unlink(h->tmp);
        h5_free(h);
        errno = saved;
        return -1;
    }
    /* make the rename itself durable */
    char *dir = strdup(h->path);
    if (dir) {
        char *slash = strrchr(dir, '/');
        const char *d = ".";
        if (slash) {
            *slash = 0;
            d = *dir ? dir : "/";
        }
        int dfd = open(d, O_RDONLY | O_DIRECTORY);
        if (dfd >= 0) {
            fsync(dfd);
            close(dfd);
        }
        free(dir);
    }
    h5_free(h);
    return 0;
}

void pk_h5_abort(pk_h5 *h)
{
    if (!h)
        return;
    h5_close_all(h);
    close(h->fd);
    unlink(h->tmp);
    h5_free(h);
}

/* Elements of an attribute's or dataset's dataspace; -1 if none. */
static hssize_t space_points(hid_t space)
{
    if (space < 0)
        return -1;
    hssize_t n = H5Sget_simple_extent_npoints(space);
    H5Sclose(space);
    return n;
}

/* A dataset's extent when it has `rank` dimensions; -1 otherwise. */
static int dataset_dims(hid_t d, int rank, hsize_t *dims)
{
    hid_t s = d >= 0 ? H5Dget_space(d) : -1;
    int ok = s >= 0 && H5Sget_simple_extent_ndims(s) == rank &&
        H5Sget_simple_extent_dims(s, dims, NULL) == rank;
    if (s >= 0)
        H5Sclose(s);
    return ok ? 0 : -1;
}

/* The box group: dimension, boundary[dim], edges[dim].  Every read is
 * checked against its buffer first: the file is not trusted. */
static int read_box(hid_t f, const char *path, pk_box *b, char *err, size_t errlen)
{
    hid_t box = H5Gopen2(f, "particles/grains/box", H5P_DEFAULT);
    if (box < 0) {
        snprintf(err, errlen, "%s: no /particles/grains/box", path);
        return -1;
    }
    int rc = -1, dim = 0;
    hid_t a = H5Aopen(box, "dimension", H5P_DEFAULT);
    if (a < 0 || space_points(H5Aget_space(a)) != 1 || H5Aread(a, H5T_NATIVE_INT, &dim) < 0 ||
        (dim != 2 && dim != 3)) {
        snprintf(err, errlen, "%s: bad box dimension", path);
        goto out;
    }
    H5Aclose(a);
    a = -1;
    b->dim = dim;
    char names[PK_MAXDIM][9];
    hid_t t = string_type(sizeof names[0]);
    a = H5Aopen(box, "boundary", H5P_DEFAULT);
    if (a >= 0 && space_points(H5Aget_space(a)) == dim && H5Aread(a, t, names) >= 0)
        for (int k = 0; k < dim; k++) {
            names[k][sizeof names[k] - 1] = 0;
            b->periodic[k] = strcmp(names[k], "periodic") == 0;
        }
    H5Tclose(t);
    hsize_t n;
    hid_t d = H5Dopen2(box, "edges", H5P_DEFAULT);
    if (dataset_dims(d, 1, &n) != 0 || n != (hsize_t)dim ||
        H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, b->L) < 0)
        snprintf(err, errlen, "%s: bad box edges", path);
    else
        rc = 0;
    if (d >= 0)
        H5Dclose(d);
out:
    if (a >= 0)
        H5Aclose(a);
    H5Gclose(box);
    return rc;
}

/* Read dataset `name` of extent dims[rank] into buf (native type t). */
static int read_exact(hid_t f, const char *name, hid_t t, int rank, const hsize_t *want, void *buf)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    hsize_t dims[2];
    int ok = dataset_dims(d, rank, dims) == 0;
    for (int k = 0; ok && k < rank; k++)
        ok = dims[k] == want[k];
    ok = ok && (want[0] == 0 || H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    if (d >= 0)
        H5Dclose(d);
    return ok ? 0 : -1;
}

int pk_h5_read_particles(const char *path, pk_box *b, pk_particles *p, char *err, size_t errlen)
{
    quiet_hdf5();
    memset(b, 0, sizeof *b);
    memset(p, 0, sizeof *p);
    /* Check the file through a descriptor (a regular file, not a FIFO or a
     * device), then let HDF5 open that very file by its /proc name. */
    int fd = pk_input_open(path, 0, err, errlen);
    if (fd < 0)
        return -1;
    struct stat st;
    char fdpath[64];
    snprintf(fdpath, sizeof fdpath, "/proc/self/fd/%d", fd);
    hid_t f = fstat(fd, &st) == 0
        ? H5Fopen(access(fdpath, R_OK) == 0 ? fdpath : path, H5F_ACC_RDONLY, H5P_DEFAULT)
        : -1;
    close(fd);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as HDF5", path);
        return -1;
    }
    int rc = -1;
    if (read_box(f, path, b, err, errlen) != 0)
        goto out;
    const int dim = b->dim;
    hsize_t n;
    hid_t d = H5Dopen2(f, "particles/grains/radius", H5P_DEFAULT);
    int have = dataset_dims(d, 1, &n) == 0;
    if (d >= 0)
        H5Dclose(d);
    if (!have) {
        snprintf(err, errlen, "%s: no /particles/grains/radius", path);
        goto out;
    }
    /* Each grain takes at least its radius' 8 bytes in a packd file: a
     * larger count is a forged header, not a packing to allocate for. */
    if (n > (hsize_t)st.st_size / sizeof(double)) {
        snprintf(err, errlen, "%s: declares %llu grains, more than its %lld bytes hold", path,
                 (unsigned long long)n, (long long)st.st_size);
        goto out;
    }
    if (pk_particles_init(p, dim, (size_t)n + 1) != 0) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    p->n = (size_t)n;
    double *pos = malloc(((size_t)n + 1) * (size_t)dim * sizeof *pos);
    hsize_t pdims[2] = {n, (hsize_t)dim};
    if (pos && read_exact(f, "particles/grains/radius", H5T_NATIVE_DOUBLE, 1, &n, p->r) == 0 &&
        read_exact(f, "particles/grains/position", H5T_NATIVE_DOUBLE, 2, pdims, pos) == 0 &&
        read_exact(f, "particles/grains/species", H5T_NATIVE_INT32, 1, &n, p->species) == 0) {
        for (size_t i = 0; i < (size_t)n; i++)
            for (int k = 0; k < 3; k++)
                p->x[3 * i + (size_t)k] = k < dim ? pos[i * (size_t)dim + (size_t)k] : 0.0;
        rc = 0;
    } else {
        snprintf(err, errlen,
                 "%s: cannot read grain datasets (radius [N], position [N][%d], "
                 "species [N])",
                 path, dim);
        pk_particles_free(p);
    }
    free(pos);
out:
    H5Fclose(f);
    return rc;
}

int pk_h5_read_unit(const char *path, char *unit, size_t n)
{
    quiet_hdf5();
    unit[0] = 0;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return -1;
    hid_t d = H5Dopen2(f, "particles/grains/position", H5P_DEFAULT);
    hid_t a = d >= 0 && H5Aexists(d, "unit") > 0 ? H5Aopen(d, "unit", H5P_DEFAULT) : -1;
    hid_t t = a >= 0 ? H5Aget_type(a) : -1;
    int rc = -1;
    if (t >= 0 && H5Tget_class(t) == H5T_STRING) {
        hid_t mt = H5Tcopy(H5T_C_S1);
        if (H5Tis_variable_str(t) > 0) {
            char *v = NULL;
            H5Tset_size(mt, H5T_VARIABLE);
            if (H5Aread(a, mt, &v) >= 0 && v) {
                snprintf(unit, n, "%s", v);
                H5free_memory(v);
                rc = 0;
            }
        } else {
            size_t len = H5Tget_size(t);
            char *v = calloc(len + 1, 1);
            H5Tset_size(mt, len + 1);
            if (v && H5Aread(a, mt, v) >= 0) {
                snprintf(unit, n, "%s", v);
                rc = 0;
            }
            free(v);
        }
        H5Tclose(mt);
    }
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
    if (d >= 0)
        H5Dclose(d);
    H5Fclose(f);
    return rc;
}
