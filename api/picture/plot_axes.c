/* plot_axes.c — axes, ticks, lines and legends of the plots (contract in
 * plot_axes.h). */
#include "plot_axes.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "picture_canvas.h"

#define TICK_FONT 11.0
#define TITLE_FONT 12.0
#define MAX_TICKS 64
#define LEGEND_ROW 16.0
#define LEGEND_PAD 8.0
#define LEGEND_SWATCH 26.0
#define LEGEND_INSET 10.0

/* 1, 2, 5 or 10 times a power of ten, the first ≥ raw. */
static double nice_step(double raw)
{
    double p = pow(10, floor(log10(raw))), m = raw / p;
    return (m <= 1 + 1e-9 ? 1 : m <= 2 + 1e-9 ? 2 : m <= 5 + 1e-9 ? 5 : 10) * p;
}

static double linear_step(const pk_plot_axis *a)
{
    double step = nice_step((a->hi - a->lo) / 5);
    return a->integer && step < 1 ? 1 : step;
}

void pk_plot_axis_fit(pk_plot_axis *a, double lo, double hi, int log)
{
    int integer = a->integer;
    memset(a, 0, sizeof *a);
    a->log = log;
    a->integer = integer && !log;
    if (log) {
        if (!(lo > 0) || !isfinite(lo) || !isfinite(hi) || hi < lo)
            lo = hi = 1;
        double k = floor(log10(lo)), m = lo / pow(10, k);
        a->lo = (m >= 5 - 1e-9 ? 5 : m >= 2 - 1e-9 ? 2 : 1) * pow(10, k);
        a->hi = nice_step(hi);
        if (a->hi <= a->lo)
            a->hi = 10 * a->lo;
        return;
    }
    if (!isfinite(lo) || !isfinite(hi) || hi < lo)
        lo = 0, hi = 1;
    if (hi == lo) {
        double pad = lo != 0 ? 0.1 * fabs(lo) : 1;
        lo -= pad;
        hi += pad;
    }
    a->lo = lo;
    a->hi = hi;
    double step = linear_step(a);
    a->lo = floor(lo / step + 1e-9) * step;
    a->hi = ceil(hi / step - 1e-9) * step;
    double big = fmax(fabs(a->lo), fabs(a->hi));
    if (big >= 1e4 || big < 1e-2)
        a->exp10 = 3 * (int)floor(log10(big) / 3);
}

/* A value a plot can show: finite, and not the ±1.8e308 result files write
 * for a non-finite figure. */
static int plottable(double v) { return isfinite(v) && fabs(v) < 1e300; }

int pk_plot_range(const double *v, size_t n, int log, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (plottable(v[i]) && (!log || v[i] > 0)) {
            *lo = fmin(*lo, v[i]);
            *hi = fmax(*hi, v[i]);
        }
    return *lo <= *hi;
}

/* Where v lies along the axis, 0 at lo and 1 at hi. */
static double frac(const pk_plot_axis *a, double v)
{
    return a->log ? log10(v / a->lo) / log10(a->hi / a->lo) : (v - a->lo) / (a->hi - a->lo);
}

double pk_plot_px(const pk_plot *p, double x)
{
    return p->left + frac(&p->x, x) * (p->right - p->left);
}

double pk_plot_py(const pk_plot *p, double y)
{
    return p->bottom - frac(&p->y, y) * (p->bottom - p->top);
}

/* "⁻¹²" for -12. */
static void superscript(int e, char *out, size_t n)
{
    static const char *const digit[] = {"\u2070", "\u00b9", "\u00b2", "\u00b3", "\u2074",
                                        "\u2075", "\u2076", "\u2077", "\u2078", "\u2079"};
    char dec[16];
    snprintf(dec, sizeof dec, "%d", e);
    out[0] = 0;
    for (const char *c = dec; *c; c++)
        strncat(out, *c == '-' ? "\u207b" : digit[*c - '0'], n - strlen(out) - 1);
}

/* The ticks of an axis: 1-2-5 steps on a linear one; on a log one every
 * 1, 2, 5 of each decade up to three decades, whole decades beyond. */
static int ticks(const pk_plot_axis *a, double *t)
{
    int n = 0;
    if (!a->log) {
        double step = linear_step(a);
        for (double k = ceil(a->lo / step - 1e-9); k * step <= a->hi + 1e-9 * step && n < MAX_TICKS;
             k++)
            t[n++] = fabs(k) < 0.5 ? 0 : k * step;
        return n;
    }
    double span = log10(a->hi / a->lo);
    int stride = span <= 3.01 ? 1 : (int)ceil(span / 8);
    static const double mant[] = {1, 2, 5};
    for (int e = (int)floor(log10(a->lo)); e <= (int)ceil(log10(a->hi)); e++)
        for (int m = 0; m < (stride == 1 ? 3 : 1); m++) {
            if (stride > 1 && e % stride != 0)
                continue;
            double v = mant[m] * pow(10, e);
            if (v >= a->lo * (1 - 1e-9) && v <= a->hi * (1 + 1e-9) && n < MAX_TICKS)
                t[n++] = v;
        }
    return n;
}

static void tick_label(const pk_plot_axis *a, double v, char *out, size_t n)
{
    if (!a->log) {
        snprintf(out, n, "%g", v / pow(10, a->exp10));
        return;
    }
    if (v >= 1e-3 && v < 1e5) {
        snprintf(out, n, "%g", v);
        return;
    }
    int e = (int)floor(log10(v) + 1e-9);
    double m = v / pow(10, e);
    char sup[48];
    superscript(e, sup, sizeof sup);
    if (fabs(m - 1) < 1e-6)
        snprintf(out, n, "10%s", sup);
    else
        snprintf(out, n, "%g\u00b710%s", m, sup);
}

static void grid_line(cairo_t *cr, double x0, double y0, double x1, double y1)
{
    cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
    cairo_set_line_width(cr, 0.5);
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, x1, y1);
    cairo_stroke(cr);
}

void pk_plot_grid_x(cairo_t *cr, const pk_plot *p)
{
    double t[MAX_TICKS];
    char label[64];
    int n = ticks(&p->x, t);
    for (int i = 0; i < n; i++) {
        double x = pk_plot_px(p, t[i]);
        grid_line(cr, x, p->top, x, p->bottom);
        tick_label(&p->x, t[i], label, sizeof label);
        cairo_set_source_rgb(cr, 0, 0, 0);
        pk_canvas_text(cr, x, p->bottom + 8, 0.5, 0, TICK_FONT, label);
    }
}

void pk_plot_grid_y(cairo_t *cr, const pk_plot *p, int right)
{
    double t[MAX_TICKS];
    char label[64];
    int n = ticks(&p->y, t);
    for (int i = 0; i < n; i++) {
        double y = pk_plot_py(p, t[i]);
        if (right) {
            cairo_set_source_rgb(cr, 0, 0, 0);
            cairo_set_line_width(cr, 1);
            cairo_move_to(cr, p->right - 5, y);
            cairo_line_to(cr, p->right, y);
            cairo_stroke(cr);
        } else {
            grid_line(cr, p->left, y, p->right, y);
        }
        tick_label(&p->y, t[i], label, sizeof label);
        cairo_set_source_rgb(cr, 0, 0, 0);
        pk_canvas_text(cr, right ? p->right + 8 : p->left - 8, y, right ? 0 : 1, 0.5, TICK_FONT,
                       label);
    }
}

/* "name [unit]", "name [×10³ unit]", or the name alone. */
static void axis_title(const pk_plot_axis *a, const char *name, const char *unit, char *out,
                       size_t n)
{
    int has_unit = unit && *unit;
    if (!a->log && a->exp10) {
        char sup[48];
        superscript(a->exp10, sup, sizeof sup);
        snprintf(out, n, "%s [\u00d710%s%s%s]", name, sup, has_unit ? " " : "",
                 has_unit ? unit : "");
    } else if (has_unit) {
        snprintf(out, n, "%s [%s]", name, unit);
    } else {
        snprintf(out, n, "%s", name);
    }
}

void pk_plot_frame(cairo_t *cr, const pk_plot *p, const char *x_name, const char *x_unit)
{
    char title[256];
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, p->left, p->top, p->right - p->left, p->bottom - p->top);
    cairo_stroke(cr);
    axis_title(&p->x, x_name, x_unit, title, sizeof title);
    pk_canvas_text(cr, (p->left + p->right) / 2, p->bottom + 42, 0.5, 0.5, TITLE_FONT, title);
}

void pk_plot_title_y(cairo_t *cr, const pk_plot *p, int right, const char *name, const char *unit,
                     const pk_plot_style *colour)
{
    char title[256];
    axis_title(&p->y, name, unit, title, sizeof title);
    cairo_save(cr);
    cairo_translate(cr, right ? p->right + 58 : p->left - 52, (p->top + p->bottom) / 2);
    cairo_rotate(cr, right ? M_PI / 2 : -M_PI / 2);
    if (colour)
        cairo_set_source_rgb(cr, colour->r, colour->g, colour->b);
    else
        cairo_set_source_rgb(cr, 0, 0, 0);
    pk_canvas_text(cr, 0, 0, 0.5, 0.5, TITLE_FONT, title);
    cairo_restore(cr);
}

static int shown(const pk_plot *p, double x, double y)
{
    return plottable(x) && plottable(y) && (!p->x.log || x > 0) && (!p->y.log || y > 0);
}

static void set_style(cairo_t *cr, const pk_plot_style *s)
{
    static const double dash[] = {6, 4};
    cairo_set_source_rgb(cr, s->r, s->g, s->b);
    cairo_set_line_width(cr, s->width > 0 ? s->width : 1.5);
    cairo_set_dash(cr, dash, s->dashed ? 2 : 0, 0);
}

void pk_plot_line(cairo_t *cr, const pk_plot *p, const double *x, const double *y, size_t n,
                  const pk_plot_style *s)
{
    cairo_save(cr);
    cairo_rectangle(cr, p->left - 4, p->top - 4, p->right - p->left + 8, p->bottom - p->top + 8);
    cairo_clip(cr); /* a little beyond the frame: dots on its edge stay whole */
    set_style(cr, s);
    int pen = 0;
    for (size_t i = 0; s->markers < 2 && i < n; i++) {
        if (!shown(p, x[i], y[i])) {
            pen = 0;
            continue;
        }
        if (pen)
            cairo_line_to(cr, pk_plot_px(p, x[i]), pk_plot_py(p, y[i]));
        else
            cairo_move_to(cr, pk_plot_px(p, x[i]), pk_plot_py(p, y[i]));
        pen = 1;
    }
    cairo_stroke(cr);
    for (size_t i = 0; s->markers && i < n; i++)
        if (shown(p, x[i], y[i])) {
            cairo_arc(cr, pk_plot_px(p, x[i]), pk_plot_py(p, y[i]), 3, 0, 2 * M_PI);
            cairo_fill(cr);
        }
    cairo_restore(cr);
}

/* Where the legend of n rows goes in a corner: (x, y) top-left, w × h. */
static void legend_box(cairo_t *cr, const pk_plot *p, int corner, const char *const *texts, int n,
                       double box[4])
{
    double wide = 0;
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, TICK_FONT);
    for (int i = 0; i < n; i++) {
        cairo_text_extents_t e;
        cairo_text_extents(cr, texts[i], &e);
        wide = fmax(wide, e.x_advance);
    }
    box[2] = 2 * LEGEND_PAD + LEGEND_SWATCH + 8 + wide;
    box[3] = 2 * LEGEND_PAD + n * LEGEND_ROW - 4;
    box[0] = corner % 2 ? p->right - LEGEND_INSET - box[2] : p->left + LEGEND_INSET;
    box[1] = corner < 2 ? p->top + LEGEND_INSET : p->bottom - LEGEND_INSET - box[3];
}

void pk_plot_legend(cairo_t *cr, const pk_plot *p, int corner, const pk_plot_style *const *styles,
                    const char *const *texts, int n)
{
    double box[4];
    legend_box(cr, p, corner, texts, n, box);
    double x = box[0], y = box[1];
    cairo_rectangle(cr, x, y, box[2], box[3]);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    cairo_set_line_width(cr, 0.75);
    cairo_stroke(cr);
    for (int i = 0; i < n; i++) {
        double yy = y + LEGEND_PAD + i * LEGEND_ROW + LEGEND_ROW / 2 - 2;
        set_style(cr, styles[i]);
        if (styles[i]->markers < 2) {
            cairo_move_to(cr, x + LEGEND_PAD, yy);
            cairo_line_to(cr, x + LEGEND_PAD + LEGEND_SWATCH, yy);
            cairo_stroke(cr);
        }
        if (styles[i]->markers) {
            cairo_arc(cr, x + LEGEND_PAD + LEGEND_SWATCH / 2, yy, 3, 0, 2 * M_PI);
            cairo_fill(cr);
        }
        cairo_set_dash(cr, NULL, 0, 0);
        cairo_set_source_rgb(cr, 0, 0, 0);
        pk_canvas_text(cr, x + LEGEND_PAD + LEGEND_SWATCH + 8, yy, 0, 0.5, TICK_FONT, texts[i]);
    }
}

int pk_plot_free_corner(cairo_t *cr, const pk_plot *p, const char *const *texts, int rows,
                        const double *x, const double *const *ys, int ny, size_t n)
{
    static const int order[4] = {1, 0, 3, 2}; /* on a tie: top-right first */
    size_t fewest = SIZE_MAX;
    int best = 1;
    for (int c = 0; c < 4; c++) {
        double box[4];
        legend_box(cr, p, order[c], texts, rows, box);
        size_t hits = 0;
        for (int k = 0; k < ny; k++)
            for (size_t i = 0; i < n; i++) { /* the points and 8 samples of each segment */
                int last = i + 1 == n;
                for (int t = 0; t < (last ? 1 : 8); t++) {
                    double xa = x[i], ya = ys[k][i];
                    if (!shown(p, xa, ya))
                        break;
                    double px = pk_plot_px(p, xa), py = pk_plot_py(p, ya);
                    if (!last && shown(p, x[i + 1], ys[k][i + 1])) {
                        px += t / 8.0 * (pk_plot_px(p, x[i + 1]) - px);
                        py += t / 8.0 * (pk_plot_py(p, ys[k][i + 1]) - py);
                    }
                    hits += px >= box[0] - 4 && px <= box[0] + box[2] + 4 && py >= box[1] - 4 &&
                        py <= box[1] + box[3] + 4;
                }
            }
        if (hits < fewest) {
            fewest = hits;
            best = order[c];
        }
    }
    return best;
}

void pk_plot_heading(cairo_t *cr, const pk_plot *p, const char *text)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    pk_canvas_text(cr, p->left, p->top / 2, 0, 0.5, 13, text);
}
