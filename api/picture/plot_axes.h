/* plot_axes.h — the axes every plot shares: a plot area on a canvas, linear
 * or logarithmic axes fitted to the data, grid lines with tick labels, axis
 * titles, polylines with markers, and a boxed legend. */
#ifndef PK_PLOT_AXES_H
#define PK_PLOT_AXES_H

#include <cairo.h>
#include <stddef.h>

typedef struct pk_plot_axis {
    double lo, hi; /* the range shown, in data values (> 0 on a log axis) */
    int log;
    int exp10;   /* linear tick labels are v / 10^exp10; the title says ×10^exp10 */
    int integer; /* linear ticks on whole numbers only (steps, counts) */
} pk_plot_axis;

typedef struct pk_plot {
    double left, top, right, bottom; /* the plot area on the canvas */
    pk_plot_axis x, y;
} pk_plot;

typedef struct pk_plot_style {
    double r, g, b;
    double width;
    int dashed;
    int markers; /* 1: a dot on every point; 2: dots without the line */
} pk_plot_style;

/* An axis over the data range [lo, hi] (as pk_plot_range finds it):
 * linear axes widen to whole tick steps, log axes to the 1-2-5 values
 * around the range. */
void pk_plot_axis_fit(pk_plot_axis *a, double lo, double hi, int log);
/* The range of the n values of v a plot can show (finite and below 1e300
 * in magnitude: result files write ±1.8e308 for a non-finite figure; log:
 * > 0 only); 0 when there is none. */
int pk_plot_range(const double *v, size_t n, int log, double *lo, double *hi);

/* Canvas coordinates of data values (x on p->x, y on p->y). */
double pk_plot_px(const pk_plot *p, double x);
double pk_plot_py(const pk_plot *p, double y);

/* Vertical grid lines and tick labels under the plot area. */
void pk_plot_grid_x(cairo_t *cr, const pk_plot *p);
/* Tick labels of p->y beside the area (right = 0: left, with horizontal
 * grid lines; 1: on the right, a second axis without grid lines). */
void pk_plot_grid_y(cairo_t *cr, const pk_plot *p, int right);
/* The frame of the area and the axis titles: the x title under the axis,
 * the y title rotated beside it (left or right), both in black.  A title
 * names the quantity and its unit ("" or NULL: dimensionless); a ×10^k
 * factor of the axis is added. */
void pk_plot_frame(cairo_t *cr, const pk_plot *p, const char *x_name, const char *x_unit);
void pk_plot_title_y(cairo_t *cr, const pk_plot *p, int right, const char *name, const char *unit,
                     const pk_plot_style *colour);

/* The polyline through (x[i], y[i]), broken where a point cannot be shown
 * (see pk_plot_range), clipped to the area. */
void pk_plot_line(cairo_t *cr, const pk_plot *p, const double *x, const double *y, size_t n,
                  const pk_plot_style *s);

/* A legend of n rows in a box in a corner of the area (0 top-left,
 * 1 top-right, 2 bottom-left, 3 bottom-right). */
void pk_plot_legend(cairo_t *cr, const pk_plot *p, int corner, const pk_plot_style *const *styles,
                    const char *const *texts, int n);

/* The corner (as pk_plot_legend numbers them) where the legend of these
 * rows covers the fewest of the polylines (x, ys[k]), k < ny, of n points. */
int pk_plot_free_corner(cairo_t *cr, const pk_plot *p, const char *const *texts, int rows,
                        const double *x, const double *const *ys, int ny, size_t n);

/* A title line above the area. */
void pk_plot_heading(cairo_t *cr, const pk_plot *p, const char *text);

#endif
