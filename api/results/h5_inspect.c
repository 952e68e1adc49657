/* h5_inspect.c — a JSON view of a result file (`packd inspect`, results document).
 * Contract: api/results/h5_inspect.h. */
#include "h5_inspect.h"
#include "result_digest.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "h5_result.h"

typedef struct {
    json_t *obj;
    size_t max_array;
} visit_ctx;

static json_t *read_dataset(hid_t d, size_t max_array)
{
    hid_t t = H5Dget_type(d), s = H5Dget_space(d);
    int rank = H5Sget_simple_extent_ndims(s);
    hsize_t dims[8] = {0};
    if (rank > 0 && rank <= 8)
        H5Sget_simple_extent_dims(s, dims, NULL);
    hsize_t total = 1;
    for (int k = 0; k < rank; k++)
        total *= dims[k];
    H5T_class_t cls = H5Tget_class(t);
    json_t *out = NULL;
    if (cls == H5T_STRING && rank == 0) {
        size_t n = H5Tget_size(t);
        char *buf = calloc(n + 1, 1);
        hid_t mt = H5Tcopy(t);
        if (buf && H5Dread(d, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0)
            out = json_string(buf);
        H5Tclose(mt);
        free(buf);
    } else if ((cls == H5T_FLOAT || cls == H5T_INTEGER) && rank <= 5 && total <= max_array) {
        int is_int = cls == H5T_INTEGER;
        void *buf = malloc((size_t)(total ? total : 1) * 8);
        if (buf &&
            H5Dread(d, is_int ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                    buf) >= 0) {
            if (rank == 0) {
                out = is_int ? json_integer((json_int_t)((long long *)buf)[0])
                             : json_real(((double *)buf)[0]);
            } else {
                /* nested arrays, row-major: [S][d][d] as S lists of d lists */
                json_t *flat = json_array();
                for (hsize_t i = 0; i < total; i++)
                    json_array_append_new(flat,
                                          is_int ? json_integer((json_int_t)((long long *)buf)[i])
                                                 : json_real(((double *)buf)[i]));
                for (int k = rank - 1; k > 0; k--) {
                    json_t *up = json_array();
                    for (size_t i = 0; i < json_array_size(flat); i += dims[k]) {
                        json_t *row = json_array();
                        for (hsize_t j = 0; j < dims[k]; j++)
                            json_array_append(row, json_array_get(flat, i + j));
                        json_array_append_new(up, row);
                    }
                    json_decref(flat);
                    flat = up;
                }
                out = flat;
            }
        }
        free(buf);
    }
    if (!out) {
        json_t *shape = json_array();
        for (int k = 0; k < rank; k++)
            json_array_append_new(shape, json_integer((json_int_t)dims[k]));
        out = json_pack("{s:o}", "shape", shape);
    }
    H5Sclose(s);
    H5Tclose(t);
    return out;
}

/* HDF5 1.12 renamed the object-visit API; Debian 12 ships 1.10. */
#if H5_VERSION_GE(1, 12, 0)
typedef H5O_info2_t obj_info;
#define visit_objects(g, fn, ctx) H5Ovisit3(g, H5_INDEX_NAME, H5_ITER_INC, fn, ctx, H5O_INFO_BASIC)
#else
typedef H5O_info_t obj_info;
#define visit_objects(g, fn, ctx) H5Ovisit2(g, H5_INDEX_NAME, H5_ITER_INC, fn, ctx, H5O_INFO_BASIC)
#endif

static herr_t visit(hid_t obj, const char *name, const obj_info *info, void *vctx)
{
    visit_ctx *c = vctx;
    if (info->type != H5O_TYPE_DATASET)
        return 0;
    hid_t d = H5Dopen2(obj, name, H5P_DEFAULT);
    if (d < 0)
        return 0;
    /* an H5MD time-dependent element X is listed as X (its value); its step
     * and time appear once, under the element that holds them (a visit sees
     * each object once, the shared ones at their first name) */
    char key[512];
    size_t len = strlen(name);
    snprintf(key, sizeof key, "%s", name);
    if (len > 6 && !strcmp(name + len - 6, "/value"))
        key[len - 6] = 0;
    json_object_set_new(c->obj, key, read_dataset(d, c->max_array));
    H5Dclose(d);
    return 0;
}

json_t *pk_h5_inspect(const char *path, size_t max_array, char *err, size_t errlen)
{
    pk_box b;
    pk_particles p;
    if (pk_h5_read_particles(path, &b, &p, err, errlen) != 0)
        return NULL;
    json_t *out = json_object();
    json_t *box = json_object(), *edges = json_array(), *per = json_array();
    for (int k = 0; k < b.dim; k++) {
        json_array_append_new(edges, json_real(b.L[k]));
        json_array_append_new(per, json_boolean(b.periodic[k]));
    }
    json_object_set_new(box, "edges", edges);
    json_object_set_new(box, "periodic", per);
    json_object_set_new(out, "dim", json_integer(b.dim));
    json_object_set_new(out, "box", box);
    json_object_set_new(out, "grains", json_integer((json_int_t)p.n));
    double rmin = p.n ? p.r[0] : 0, rmax = rmin;
    for (size_t i = 0; i < p.n; i++) {
        rmin = p.r[i] < rmin ? p.r[i] : rmin;
        rmax = p.r[i] > rmax ? p.r[i] : rmax;
    }
    json_object_set_new(out, "d_min", json_real(2 * rmin));
    json_object_set_new(out, "d_max", json_real(2 * rmax));
    json_object_set_new(out, "phi", json_real(pk_particles_solid_measure(&p) / pk_box_measure(&b)));
    pk_particles_free(&p);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f >= 0) {
        visit_ctx c = {json_object(), max_array};
        hid_t g = H5Gopen2(f, "observables", H5P_DEFAULT);
        if (g >= 0) {
            visit_objects(g, visit, &c);
            H5Gclose(g);
        }
        json_object_set_new(out, "observables", c.obj);
        hid_t pg = H5Gopen2(f, "parameters", H5P_DEFAULT);
        if (pg >= 0) {
            hid_t d = H5Dopen2(pg, "job", H5P_DEFAULT);
            if (d >= 0) {
                json_t *s = read_dataset(d, 0);
                json_t *job = json_is_string(s) ? json_loads(json_string_value(s), 0, NULL) : NULL;
                if (job)
                    json_object_set_new(out, "job", job);
                json_decref(s);
                H5Dclose(d);
            }
            H5Gclose(pg);
        }
        H5Fclose(f);
    }
    char stored[65], computed[65];
    if (pk_result_digest_stored(path, stored) == 0) {
        json_object_set_new(out, "result_digest", json_string(stored));
        json_object_set_new(
            out, "result_digest_verified",
            json_boolean(pk_result_digest_file(path, computed) == 0 && !strcmp(stored, computed)));
    }
    return out;
}
