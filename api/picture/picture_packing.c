/* picture_packing.c — a packing drawn as the papers draw it (picture.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/space/box.h"
#include "api/results/h5_result.h"
#include "picture_canvas.h"
#include "picture_internal.h"
#include "picture_mesh.h"

#define PANEL 720.0 /* the longer box side, in pt/px */
#define MARGIN 36.0
#define LEGEND 170.0   /* the size-class legend's column */
#define LEGEND_ROWS 16 /* classes beyond: every k-th shown */

typedef struct frame {
    double x0, y0, s, Lx, Ly; /* panel origin (top-left), scale, box extent */
} frame;

static double fx(const frame *f, double x) { return f->x0 + x * f->s; }
static double fy(const frame *f, double y) { return f->y0 + (f->Ly - y) * f->s; }

/* The box outline: walls solid, periodic sides dashed. */
static void draw_frame(cairo_t *cr, const frame *f, const pk_box *b)
{
    const double dash[] = {6, 4};
    double corners[5][2] = {{0, 0}, {f->Lx, 0}, {f->Lx, f->Ly}, {0, f->Ly}, {0, 0}};
    cairo_set_line_width(cr, 1.5);
    cairo_set_source_rgb(cr, 0, 0, 0);
    for (int k = 0; k < 4; k++) {
        int axis = k % 2 == 0 ? 1 : 0; /* bottom/top sides bound y, left/right bound x */
        cairo_set_dash(cr, dash, b->periodic[axis] ? 2 : 0, 0);
        cairo_move_to(cr, fx(f, corners[k][0]), fy(f, corners[k][1]));
        cairo_line_to(cr, fx(f, corners[k + 1][0]), fy(f, corners[k + 1][1]));
        cairo_stroke(cr);
    }
    cairo_set_dash(cr, NULL, 0, 0);
}

/* One disk of radius rr at (x, y), with its periodic images on x and y when
 * it crosses a periodic side; a cut disk gets a dashed outline. */
static void draw_disk(cairo_t *cr, const frame *f, const pk_box *b, double x, double y, double rr,
                      int species, int classes, double shade)
{
    double L[2] = {f->Lx, f->Ly}, c[2] = {x, y};
    int lo[2], hi[2];
    for (int k = 0; k < 2; k++) {
        lo[k] = b->periodic[k] && c[k] + rr > L[k] ? -1 : 0;
        hi[k] = b->periodic[k] && c[k] - rr < 0 ? 1 : 0;
    }
    int cut = lo[0] || hi[0] || lo[1] || hi[1];
    static const double dash[] = {2, 2};
    for (int i = lo[0]; i <= hi[0]; i++)
        for (int j = lo[1]; j <= hi[1]; j++) {
            cairo_new_path(cr);
            cairo_arc(cr, fx(f, x + i * L[0]), fy(f, y + j * L[1]), rr * f->s, 0, 2 * M_PI);
            pk_canvas_class_colour(cr, species, classes, shade);
            cairo_fill_preserve(cr);
            cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
            cairo_set_line_width(cr, cut ? 0.9 : 0.4);
            cairo_set_dash(cr, dash, cut ? 2 : 0, 0);
            cairo_stroke(cr);
        }
    cairo_set_dash(cr, NULL, 0, 0);
}

static void clip_to(cairo_t *cr, const frame *f)
{
    cairo_rectangle(cr, fx(f, 0), fy(f, f->Ly), f->Lx * f->s, f->Ly * f->s);
    cairo_clip(cr);
}

/* The section z = z0 through 3D grains (and their z images when z is periodic). */
static void draw_section(cairo_t *cr, const frame *f, const pk_box *b, const pk_particles *p,
                         int classes, double z0)
{
    cairo_save(cr);
    clip_to(cr, f);
    for (size_t i = 0; i < p->n; i++)
        for (int m = b->periodic[2] ? -1 : 0; m <= (b->periodic[2] ? 1 : 0); m++) {
            double dz = p->x[3 * i + 2] + m * b->L[2] - z0, r = p->r[i];
            if (fabs(dz) < r)
                draw_disk(cr, f, b, p->x[3 * i], p->x[3 * i + 1], sqrt(r * r - dz * dz),
                          p->species[i], classes, 1.0);
        }
    cairo_restore(cr);
}

/* A tetfill result's mesh where the section plane z = z0 cuts it: each
 * tet's cut polygon outlined in dark red over the grains. */
static void draw_mesh_section(cairo_t *cr, const frame *f, const pk_picture_mesh *m, double z0)
{
    cairo_save(cr);
    clip_to(cr, f);
    cairo_set_source_rgb(cr, 0.7, 0.1, 0.1);
    cairo_set_line_width(cr, 0.6);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (size_t k = 0; k < m->nt; k++) {
        double xy[4][2];
        int n = pk_picture_mesh_cut(m, k, z0, xy);
        for (int i = 0; i < n; i++)
            (i ? cairo_line_to : cairo_move_to)(cr, fx(f, xy[i][0]), fy(f, xy[i][1]));
        if (n)
            cairo_close_path(cr);
    }
    cairo_stroke(cr);
    cairo_restore(cr);
}

static const double *zkey;
static int by_z(const void *a, const void *b)
{
    double za = zkey[3 * *(const size_t *)a + 2], zb = zkey[3 * *(const size_t *)b + 2];
    return (za > zb) - (za < zb);
}

/* Orthographic view along −z: far grains first, nearer ones brighter. */
static int draw_projection(cairo_t *cr, const frame *f, const pk_box *b, const pk_particles *p,
                           int classes)
{
    size_t *order = malloc((p->n ? p->n : 1) * sizeof *order);
    if (!order)
        return -1;
    for (size_t i = 0; i < p->n; i++)
        order[i] = i;
    zkey = p->x;
    qsort(order, p->n, sizeof *order, by_z);
    cairo_save(cr);
    clip_to(cr, f);
    for (size_t k = 0; k < p->n; k++) {
        size_t i = order[k];
        double depth = b->L[2] > 0 ? p->x[3 * i + 2] / b->L[2] : 1;
        depth = depth < 0 ? 0 : depth > 1 ? 1 : depth;
        draw_disk(cr, f, b, p->x[3 * i], p->x[3 * i + 1], p->r[i], p->species[i], classes,
                  0.35 + 0.65 * depth);
    }
    cairo_restore(cr);
    free(order);
    return 0;
}

/* The smallest and largest diameter of each size class (species). */
static void class_sizes(const pk_particles *p, int classes, double *dlo, double *dhi)
{
    for (int k = 0; k < classes; k++)
        dlo[k] = INFINITY, dhi[k] = 0;
    for (size_t i = 0; i < p->n; i++) {
        int k = p->species[i];
        dlo[k] = fmin(dlo[k], 2 * p->r[i]);
        dhi[k] = fmax(dhi[k], 2 * p->r[i]);
    }
}

/* A swatch and the diameters of each size class, top to bottom from (x, y). */
static void draw_legend(cairo_t *cr, const pk_particles *p, int classes, const char *unit, double x,
                        double y)
{
    double *dlo = malloc(2 * (size_t)classes * sizeof *dlo);
    if (!dlo)
        return;
    double *dhi = dlo + classes;
    class_sizes(p, classes, dlo, dhi);
    cairo_set_source_rgb(cr, 0, 0, 0);
    pk_canvas_text(cr, x, y, 0, 0.5, 12, "size classes (d)");
    int step = (classes + LEGEND_ROWS - 1) / LEGEND_ROWS;
    for (int k = 0, row = 1; k < classes; k += step, row++) {
        double yr = y + 20 * row;
        cairo_new_path(cr);
        cairo_arc(cr, x + 7, yr, 6, 0, 2 * M_PI);
        pk_canvas_class_colour(cr, k, classes, 1.0);
        cairo_fill_preserve(cr);
        cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
        cairo_set_line_width(cr, 0.4);
        cairo_stroke(cr);
        char label[96];
        if (dhi[k] == 0)
            snprintf(label, sizeof label, "none placed");
        else if (dhi[k] - dlo[k] <= 1e-9 * dhi[k])
            snprintf(label, sizeof label, "%.3g %s", dhi[k], unit);
        else
            snprintf(label, sizeof label, "%.3g–%.3g %s", dlo[k], dhi[k], unit);
        pk_canvas_text(cr, x + 20, yr, 0, 0.5, 11, label);
    }
    free(dlo);
}

/* A bar of a round length (1, 2 or 5 × 10^k) near a fifth of the box
 * width, left-aligned at (x, y), labelled with it. */
static void draw_scale_bar(cairo_t *cr, const frame *f, const char *unit, double x, double y)
{
    double want = f->Lx / 5, e = pow(10, floor(log10(want))), len = e;
    if (2 * e <= want)
        len = 5 * e <= want ? 5 * e : 2 * e;
    double w = len * f->s;
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2.5);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + w, y);
    cairo_stroke(cr);
    cairo_set_line_width(cr, 1);
    for (int k = 0; k < 2; k++) {
        cairo_move_to(cr, x + k * w, y - 5);
        cairo_line_to(cr, x + k * w, y + 5);
    }
    cairo_stroke(cr);
    char label[64];
    snprintf(label, sizeof label, "%g %s", len, unit);
    pk_canvas_text(cr, x + w + 8, y, 0, 0.5, 12, label);
}

int pk_picture_packing(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    pk_box b;
    pk_particles p;
    if (pk_h5_read_particles(h5_path, &b, &p, err, errlen) != 0)
        return -1;
    int classes = 1;
    double measure = 0;
    for (size_t i = 0; i < p.n; i++) {
        classes = p.species[i] + 1 > classes ? p.species[i] + 1 : classes;
        measure += b.dim == 3 ? 4.0 / 3.0 * M_PI * pow(p.r[i], 3) : M_PI * p.r[i] * p.r[i];
    }
    frame f = {.Lx = b.L[0], .Ly = b.L[1]};
    f.s = PANEL / fmax(f.Lx, f.Ly);
    int panels = b.dim == 3 ? 2 : 1;
    double pw = f.Lx * f.s, ph = f.Ly * f.s;
    pk_canvas c;
    if (pk_canvas_open(&c, out_path, panels * (pw + MARGIN) + MARGIN + LEGEND, ph + 3.5 * MARGIN,
                       err, errlen) != 0) {
        pk_particles_free(&p);
        return -1;
    }
    char unit[32], dims[128], title[320];
    if (pk_h5_read_unit(h5_path, unit, sizeof unit) != 0 || !unit[0])
        snprintf(unit, sizeof unit, "(length unit)");
    if (b.dim == 3)
        snprintf(dims, sizeof dims, "%g × %g × %g %s", b.L[0], b.L[1], b.L[2], unit);
    else
        snprintf(dims, sizeof dims, "%g × %g %s", b.L[0], b.L[1], unit);
    snprintf(title, sizeof title, "%zu grains, %d size class%s, φ = %.4f, %dD box %s", p.n, classes,
             classes > 1 ? "es" : "", measure / pk_box_measure(&b), b.dim, dims);
    cairo_set_source_rgb(c.cr, 0, 0, 0);
    pk_canvas_text(c.cr, MARGIN, MARGIN * 0.6, 0, 0.5, 14, title);
    f.x0 = MARGIN;
    f.y0 = 1.5 * MARGIN;
    int rc = 0;
    if (b.dim == 2) {
        cairo_save(c.cr);
        clip_to(c.cr, &f);
        for (size_t i = 0; i < p.n; i++)
            draw_disk(c.cr, &f, &b, p.x[3 * i], p.x[3 * i + 1], p.r[i], p.species[i], classes, 1.0);
        cairo_restore(c.cr);
        draw_frame(c.cr, &f, &b);
    } else {
        draw_section(c.cr, &f, &b, &p, classes, 0.5 * b.L[2]);
        pk_picture_mesh mesh;
        int with_mesh = pk_picture_mesh_read(h5_path, &mesh) == 0;
        if (with_mesh) {
            draw_mesh_section(c.cr, &f, &mesh, 0.5 * b.L[2]);
            pk_picture_mesh_free(&mesh);
        }
        draw_frame(c.cr, &f, &b);
        cairo_set_source_rgb(c.cr, 0, 0, 0);
        pk_canvas_text(c.cr, f.x0 + pw / 2, f.y0 + ph + 0.5 * MARGIN, 0.5, 0.5, 12,
                       with_mesh ? "section z = Lz/2 with the tet mesh" : "section z = Lz/2");
        f.x0 += pw + MARGIN;
        rc = draw_projection(c.cr, &f, &b, &p, classes);
        draw_frame(c.cr, &f, &b);
        cairo_set_source_rgb(c.cr, 0, 0, 0);
        pk_canvas_text(c.cr, f.x0 + pw / 2, f.y0 + ph + 0.5 * MARGIN, 0.5, 0.5, 12,
                       "view along -z (nearer = brighter)");
    }
    draw_scale_bar(c.cr, &(frame){.s = f.s, .Lx = b.L[0]}, unit, MARGIN,
                   1.5 * MARGIN + ph + 1.5 * MARGIN);
    draw_legend(c.cr, &p, classes, unit, panels * (pw + MARGIN) + MARGIN, 1.5 * MARGIN + 8);
    pk_particles_free(&p);
    if (rc != 0) {
        pk_canvas_abort(&c);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    return pk_canvas_finish(&c, err, errlen);
}
