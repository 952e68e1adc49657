/* picture_fe2_field.c — the macro problem of an fe2 result (picture.h): the
 * mesh deformed by the last converged load step's displacements (true
 * scale) over its undeformed outline, each element coloured by the mean von
 * Mises stress of its Gauss points, σ_mises = √(3/2 σ′:σ′) with the 2×2
 * Cauchy stress's deviator σ′ = σ − (tr σ / 2)·1 (the plane-strain σ₃₃ is
 * not computed by the RVE; docs/fe2.md), and a colour bar with its unit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "picture_canvas.h"
#include "picture_internal.h"
#include "plot_data.h"

#define W 760.0
#define H 600.0
#define MARGIN 50.0
#define BAR 90.0 /* the colour bar's column */
#define FE2 "/observables/fe2/"

/* Dataset path as doubles: the whole of it, or (last) only its last
 * block along the first axis; dims[] its shape (of that block). */
static double *read_doubles(hid_t f, const char *path, int last, hsize_t dims[3], int *rank)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    hid_t s = d >= 0 ? H5Dget_space(d) : -1;
    int r = s >= 0 ? H5Sget_simple_extent_ndims(s) : -1;
    double *v = NULL;
    if (r >= 1 && r <= 3 && H5Sget_simple_extent_dims(s, dims, NULL) == r && dims[0] > 0) {
        hsize_t start[3] = {0, 0, 0},
                count[3] = {dims[0], r > 1 ? dims[1] : 1, r > 2 ? dims[2] : 1};
        if (last)
            start[0] = dims[0] - 1, count[0] = 1;
        size_t n = (size_t)(count[0] * count[1] * count[2]);
        hid_t m = H5Screate_simple(r, count, NULL);
        v = malloc(n * sizeof *v);
        if (!v || H5Sselect_hyperslab(s, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
            H5Dread(d, H5T_NATIVE_DOUBLE, m, s, H5P_DEFAULT, v) < 0) {
            free(v);
            v = NULL;
        }
        H5Sclose(m);
        if (last)
            dims[0] = 1;
        *rank = r;
    }
    if (s >= 0)
        H5Sclose(s);
    if (d >= 0)
        H5Dclose(d);
    return v;
}

/* viridis at t in [0, 1], by five stops */
static void field_colour(cairo_t *cr, double t)
{
    static const double stop[5][3] = {{0.267, 0.005, 0.329},
                                      {0.230, 0.322, 0.546},
                                      {0.128, 0.567, 0.551},
                                      {0.369, 0.789, 0.383},
                                      {0.993, 0.906, 0.144}};
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    int k = t >= 1 ? 3 : (int)(t * 4);
    double u = t * 4 - k, c[3];
    for (int i = 0; i < 3; i++)
        c[i] = stop[k][i] + u * (stop[k + 1][i] - stop[k][i]);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
}

typedef struct field {
    hsize_t nn, ne, ng, nv; /* nodes, elements, Gauss points, nodes per element */
    double *x, *u, *el, *gel, *sig, *mises;
} field;

static void field_free(field *fd)
{
    free(fd->x), free(fd->u), free(fd->el), free(fd->gel), free(fd->sig), free(fd->mises);
}

/* The mesh, the last step's displacements and Gauss-point stresses, and
 * each element's mean von Mises stress; 0, or -1. */
static int field_read(hid_t f, field *fd)
{
    hsize_t d[3];
    int r = 0;
    if (!(fd->x = read_doubles(f, FE2 "mesh/nodes", 0, d, &r)) || r != 2 || d[1] != 2)
        return -1;
    fd->nn = d[0];
    if (!(fd->el = read_doubles(f, FE2 "mesh/elements", 0, d, &r)) || r != 2)
        return -1;
    fd->ne = d[0], fd->nv = d[1];
    if (!(fd->gel = read_doubles(f, FE2 "mesh/gauss_element", 0, d, &r)) || r != 1)
        return -1;
    fd->ng = d[0];
    if (!(fd->u = read_doubles(f, FE2 "displacement/value", 1, d, &r)) || r != 3 ||
        d[1] != fd->nn || d[2] != 2)
        return -1;
    if (!(fd->sig = read_doubles(f, FE2 "cauchy_stress/value", 1, d, &r)) || r != 3 ||
        d[1] != fd->ng || d[2] != 4)
        return -1;
    double *count = calloc(fd->ne, sizeof *count);
    fd->mises = calloc(fd->ne, sizeof *fd->mises);
    if (!count || !fd->mises) {
        free(count);
        return -1;
    }
    for (hsize_t g = 0; g < fd->ng; g++) {
        const double *s = &fd->sig[4 * g];
        double h = 0.5 * (s[0] + s[3]), a = s[0] - h, b = s[3] - h;
        double v = sqrt(1.5 * (a * a + b * b + s[1] * s[1] + s[2] * s[2]));
        long e = (long)fd->gel[g];
        if (e >= 0 && (hsize_t)e < fd->ne)
            fd->mises[e] += v, count[e] += 1;
    }
    for (hsize_t e = 0; e < fd->ne; e++)
        fd->mises[e] = count[e] > 0 ? fd->mises[e] / count[e] : NAN;
    free(count);
    return 0;
}

/* The elements as polygons through node positions x (+ u if given). */
static void trace(cairo_t *cr, const field *fd, hsize_t e, const double *u, double x0, double y0,
                  double s, double ymax)
{
    for (hsize_t k = 0; k < fd->nv; k++) {
        long a = (long)fd->el[e * fd->nv + k];
        if (a < 0 || (hsize_t)a >= fd->nn)
            continue;
        double px = fd->x[2 * a] + (u ? u[2 * a] : 0),
               py = fd->x[2 * a + 1] + (u ? u[2 * a + 1] : 0);
        (k ? cairo_line_to : cairo_move_to)(cr, x0 + px * s, y0 + (ymax - py) * s);
    }
    cairo_close_path(cr);
}

static void draw(cairo_t *cr, const field *fd, const char *unit, const char *heading)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    double vlo = INFINITY, vhi = -INFINITY;
    for (hsize_t a = 0; a < fd->nn; a++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], fmin(fd->x[2 * a + k], fd->x[2 * a + k] + fd->u[2 * a + k]));
            hi[k] = fmax(hi[k], fmax(fd->x[2 * a + k], fd->x[2 * a + k] + fd->u[2 * a + k]));
        }
    for (hsize_t e = 0; e < fd->ne; e++)
        if (isfinite(fd->mises[e]))
            vlo = fmin(vlo, fd->mises[e]), vhi = fmax(vhi, fd->mises[e]);
    if (!(vhi > vlo))
        vhi = vlo + 1;
    double s = fmin((W - 2 * MARGIN - BAR) / fmax(hi[0] - lo[0], 1e-300),
                    (H - 2.5 * MARGIN) / fmax(hi[1] - lo[1], 1e-300));
    double x0 = MARGIN - lo[0] * s, ymax = hi[1], top = 1.5 * MARGIN;
    for (hsize_t e = 0; e < fd->ne; e++) { /* deformed, coloured */
        trace(cr, fd, e, fd->u, x0, top, s, ymax);
        field_colour(cr, (fd->mises[e] - vlo) / (vhi - vlo));
        cairo_fill_preserve(cr);
        cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
        cairo_set_line_width(cr, 0.5);
        cairo_stroke(cr);
    }
    static const double dash[] = {4, 3};
    cairo_set_dash(cr, dash, 2, 0);
    cairo_set_source_rgb(cr, 0.55, 0.55, 0.55);
    cairo_set_line_width(cr, 0.8);
    for (hsize_t e = 0; e < fd->ne; e++) { /* undeformed outline */
        trace(cr, fd, e, NULL, x0, top, s, ymax);
        cairo_stroke(cr);
    }
    cairo_set_dash(cr, NULL, 0, 0);
    double bx = W - BAR + 10, by = top, bh = H - 2.5 * MARGIN; /* colour bar */
    for (int i = 0; i < 100; i++) {
        field_colour(cr, 1 - (i + 0.5) / 100);
        cairo_rectangle(cr, bx, by + bh * i / 100, 18, bh / 100 + 0.5);
        cairo_fill(cr);
    }
    char t[96];
    cairo_set_source_rgb(cr, 0, 0, 0);
    snprintf(t, sizeof t, "%.3g", vhi);
    pk_canvas_text(cr, bx + 22, by, 0, 0.5, 11, t);
    snprintf(t, sizeof t, "%.3g", vlo);
    pk_canvas_text(cr, bx + 22, by + bh, 0, 0.5, 11, t);
    snprintf(t, sizeof t, "σ_mises [%s]", unit[0] ? unit : "stress unit");
    pk_canvas_text(cr, W - 8, by - 16, 1, 0.5, 11, t);
    snprintf(t, sizeof t, "%.3g", 0.5 * (vlo + vhi));
    pk_canvas_text(cr, bx + 22, by + bh / 2, 0, 0.5, 11, t);
    pk_canvas_text(cr, MARGIN, 0.6 * MARGIN, 0, 0.5, 14, heading);
    pk_canvas_text(cr, MARGIN, H - 0.5 * MARGIN, 0, 0.5, 11,
                   "deformed at true scale (dashed: undeformed), element colour: mean over its "
                   "Gauss points");
}

int pk_picture_field(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    field fd = {0};
    char unit[32], bc[64];
    int ok = field_read(f, &fd) == 0;
    pk_plot_unit(f, FE2 "cauchy_stress", unit, sizeof unit);
    pk_plot_string(f, FE2 "boundary_condition", bc, sizeof bc);
    size_t steps = 0;
    free(pk_plot_series(f, FE2 "load_steps/time", &steps));
    pk_plot_file_close(f);
    int rc = -1;
    pk_canvas c;
    if (!ok)
        snprintf(err, errlen,
                 "%s has no fe2 field (only fe2 results have /observables/fe2/mesh and its "
                 "stresses)",
                 h5_path);
    else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        char heading[160];
        snprintf(heading, sizeof heading,
                 "FE² von Mises stress after load step %zu (RVE boundary condition: %s)", steps,
                 bc[0] ? bc : "unknown");
        draw(c.cr, &fd, unit, heading);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    field_free(&fd);
    return rc;
}
