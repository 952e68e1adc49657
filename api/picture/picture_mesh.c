/* picture_mesh.c — the tet mesh cut by a plane (contract in picture_mesh.h). */
#include "picture_mesh.h"

#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "plot_data.h"

/* Dataset path as `type`, with `per` values per row: [n][per] or flat
 * [n·per].  Rows in *n; malloc'd, NULL when absent or of another shape. */
static void *read_rows(hid_t f, const char *path, hid_t type, size_t size, hsize_t per, size_t *n)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0)
        return NULL;
    hid_t s = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    int rank = H5Sget_simple_extent_ndims(s);
    void *v = NULL;
    if (rank >= 1 && rank <= 2 && H5Sget_simple_extent_dims(s, dims, NULL) == rank &&
        (rank == 2 ? dims[1] == per : dims[0] % per == 0)) {
        *n = (size_t)(rank == 2 ? dims[0] : dims[0] / per);
        v = *n ? malloc(*n * per * size) : NULL;
        if (v && H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0) {
            free(v);
            v = NULL;
        }
    }
    H5Sclose(s);
    H5Dclose(d);
    return v;
}

int pk_picture_mesh_read(const char *h5_path, pk_picture_mesh *m)
{
    memset(m, 0, sizeof *m);
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0)
        return -1;
    m->x = read_rows(f, "/observables/tetfill/mesh_nodes", H5T_NATIVE_DOUBLE, sizeof(double), 3,
                     &m->nn);
    m->t = read_rows(f, "/observables/tetfill/mesh_tets", H5T_NATIVE_INT64, sizeof(int64_t), 4,
                     &m->nt);
    pk_plot_file_close(f);
    int ok = m->x && m->t;
    for (size_t i = 0; ok && i < 4 * m->nt; i++)
        ok = m->t[i] >= 0 && (size_t)m->t[i] < m->nn; /* the file is not trusted */
    if (!ok) {
        pk_picture_mesh_free(m);
        return -1;
    }
    return 0;
}

void pk_picture_mesh_free(pk_picture_mesh *m)
{
    free(m->x);
    free(m->t);
    memset(m, 0, sizeof *m);
}

int pk_picture_mesh_cut(const pk_picture_mesh *m, size_t k, double z0, double xy[4][2])
{
    static const int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    const double *p[4];
    for (int a = 0; a < 4; a++)
        p[a] = &m->x[3 * (size_t)m->t[4 * k + (size_t)a]];
    int n = 0;
    for (int e = 0; e < 6 && n < 4; e++) {
        const double *a = p[edge[e][0]], *b = p[edge[e][1]];
        double da = a[2] - z0, db = b[2] - z0;
        if ((da < 0) == (db < 0) || da == db) /* both on one side (a node on the plane: above) */
            continue;
        double s = da / (da - db);
        xy[n][0] = a[0] + s * (b[0] - a[0]);
        xy[n][1] = a[1] + s * (b[1] - a[1]);
        n++;
    }
    if (n < 3)
        return 0;
    /* around the centroid (a convex polygon: the plane's cut of a tet) */
    double cx = 0, cy = 0, ang[4];
    for (int i = 0; i < n; i++)
        cx += xy[i][0] / n, cy += xy[i][1] / n;
    for (int i = 0; i < n; i++)
        ang[i] = atan2(xy[i][1] - cy, xy[i][0] - cx);
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && ang[j] < ang[j - 1]; j--) {
            double t = ang[j], tx = xy[j][0], ty = xy[j][1];
            ang[j] = ang[j - 1], xy[j][0] = xy[j - 1][0], xy[j][1] = xy[j - 1][1];
            ang[j - 1] = t, xy[j - 1][0] = tx, xy[j - 1][1] = ty;
        }
    return n;
}
