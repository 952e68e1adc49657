/* picture_grading.c — the grading curve of a pack result, target against
 * achieved (picture.h). */
#include <hdf5.h>
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "api/results/h5_inspect.h"
#include "picture_canvas.h"
#include "picture_internal.h"

#define W 720.0
#define H 480.0
#define LEFT 70.0
#define RIGHT 30.0
#define TOP 50.0
#define BOTTOM 60.0

typedef struct axes {
    double lx0, lx1; /* log10 of the sieve range */
} axes;

static double ax_x(const axes *a, double d)
{
    return LEFT + (log10(d) - a->lx0) / (a->lx1 - a->lx0) * (W - LEFT - RIGHT);
}
static double ax_y(double percent) { return H - BOTTOM - percent / 100.0 * (H - TOP - BOTTOM); }

static void draw_axes(cairo_t *cr, const axes *a, const char *unit)
{
    char label[64];
    cairo_set_line_width(cr, 0.5);
    for (int p = 0; p <= 100; p += 20) { /* horizontal grid and % labels */
        cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
        cairo_move_to(cr, LEFT, ax_y(p));
        cairo_line_to(cr, W - RIGHT, ax_y(p));
        cairo_stroke(cr);
        snprintf(label, sizeof label, "%d", p);
        cairo_set_source_rgb(cr, 0, 0, 0);
        pk_canvas_text(cr, LEFT - 8, ax_y(p), 1, 0.5, 11, label);
    }
    static const double mant[] = {1, 2, 5};
    for (int e = (int)floor(a->lx0); e <= (int)ceil(a->lx1); e++) /* 1-2-5 sieve ticks */
        for (int m = 0; m < 3; m++) {
            double d = mant[m] * pow(10, e), lx = log10(d);
            if (lx < a->lx0 - 1e-9 || lx > a->lx1 + 1e-9)
                continue;
            cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
            cairo_move_to(cr, ax_x(a, d), TOP);
            cairo_line_to(cr, ax_x(a, d), H - BOTTOM);
            cairo_stroke(cr);
            snprintf(label, sizeof label, "%g", d);
            cairo_set_source_rgb(cr, 0, 0, 0);
            pk_canvas_text(cr, ax_x(a, d), H - BOTTOM + 8, 0.5, 0, 11, label);
        }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, LEFT, TOP, W - LEFT - RIGHT, H - TOP - BOTTOM);
    cairo_stroke(cr);
    snprintf(label, sizeof label, "sieve size [%s]", unit && *unit ? unit : "-");
    pk_canvas_text(cr, (LEFT + W - RIGHT) / 2, H - 18, 0.5, 0.5, 12, label);
    cairo_save(cr);
    cairo_translate(cr, 18, (TOP + H - BOTTOM) / 2);
    cairo_rotate(cr, -M_PI / 2);
    pk_canvas_text(cr, 0, 0, 0.5, 0.5, 12, "passing [%]");
    cairo_restore(cr);
}

static void draw_curve(cairo_t *cr, const axes *a, json_t *d, json_t *pass, int markers)
{
    size_t n = json_array_size(d);
    for (size_t i = 0; i < n; i++) {
        double x = ax_x(a, json_number_value(json_array_get(d, i)));
        double y = ax_y(json_number_value(json_array_get(pass, i)));
        if (i == 0)
            cairo_move_to(cr, x, y);
        else
            cairo_line_to(cr, x, y);
    }
    cairo_stroke(cr);
    for (size_t i = 0; markers && i < n; i++) {
        cairo_arc(cr, ax_x(a, json_number_value(json_array_get(d, i))),
                  ax_y(json_number_value(json_array_get(pass, i))), 3.5, 0, 2 * M_PI);
        cairo_fill(cr);
    }
}

static void legend_line(cairo_t *cr, double y, double r, double g, double b, const char *text)
{
    cairo_set_source_rgb(cr, r, g, b);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, LEFT + 14, y);
    cairo_line_to(cr, LEFT + 40, y);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    pk_canvas_text(cr, LEFT + 48, y, 0, 0.5, 11, text);
}

/* The "unit" attribute of a dataset (fixed-length string), or "" when absent. */
static void unit_of(const char *h5_path, const char *dataset, char *out, size_t n)
{
    out[0] = 0;
    hid_t f = H5Fopen(h5_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return;
    hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
    if (d >= 0 && H5Aexists(d, "unit") > 0) {
        hid_t a = H5Aopen(d, "unit", H5P_DEFAULT), t = H5Aget_type(a);
        size_t len = H5Tget_size(t);
        if (H5Tis_variable_str(t) <= 0 && len < n && H5Aread(a, t, out) >= 0)
            out[len] = 0;
        H5Tclose(t);
        H5Aclose(a);
    }
    if (d >= 0)
        H5Dclose(d);
    H5Fclose(f);
}

int pk_picture_grading(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    json_t *doc = pk_h5_inspect(h5_path, SIZE_MAX, err, errlen);
    if (!doc)
        return -1;
    json_t *obs = json_object_get(doc, "observables");
    json_t *d = json_object_get(obs, "grading/sieve_size");
    json_t *pt = json_object_get(obs, "grading/target_passing_percent");
    json_t *pa = json_object_get(obs, "grading/achieved_passing_percent");
    size_t n = json_array_size(d);
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < n; i++) {
        double v = json_number_value(json_array_get(d, i));
        if (v > 0) {
            lo = fmin(lo, v);
            hi = fmax(hi, v);
        }
    }
    if (n < 2 || json_array_size(pt) != n || json_array_size(pa) != n || !(hi > lo)) {
        snprintf(err, errlen, "%s has no grading curve (only pack results do)", h5_path);
        json_decref(doc);
        return -1;
    }
    pk_canvas c;
    if (pk_canvas_open(&c, out_path, W, H, err, errlen) != 0) {
        json_decref(doc);
        return -1;
    }
    axes a = {floor(log10(lo) * 10) / 10, ceil(log10(hi) * 10) / 10};
    char unit[32];
    unit_of(h5_path, "/observables/grading/sieve_size", unit, sizeof unit);
    draw_axes(c.cr, &a, unit);
    cairo_set_line_width(c.cr, 2);
    cairo_set_source_rgb(c.cr, 0.2, 0.2, 0.2);
    draw_curve(c.cr, &a, d, pt, 0);
    cairo_set_source_rgb(c.cr, 0.85, 0.33, 0.1);
    draw_curve(c.cr, &a, d, pa, 1);
    char text[160];
    double phi_mix = json_number_value(json_object_get(obs, "phi_mix"));
    double phi_eff = json_number_value(json_object_get(obs, "phi_resolved"));
    snprintf(text, sizeof text,
             "phi_M = %.2f %%, phi_eff = %.2f %% (grains finer than d_min are left to the matrix)",
             100 * phi_mix, 100 * phi_eff);
    cairo_set_source_rgb(c.cr, 0, 0, 0);
    pk_canvas_text(c.cr, LEFT, TOP / 2, 0, 0.5, 13, text);
    legend_line(c.cr, TOP + 16, 0.2, 0.2, 0.2, "target (the job's grading, resolved part)");
    legend_line(c.cr, TOP + 32, 0.85, 0.33, 0.1, "achieved (placed grains)");
    json_decref(doc);
    return pk_canvas_finish(&c, err, errlen);
}
