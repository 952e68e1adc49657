/* picture_canvas.c — cairo surfaces that end as SVG or PNG files
 * (contract in picture_canvas.h). */
#include "picture_canvas.h"

#include <cairo-svg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

int pk_canvas_open(pk_canvas *c, const char *path, double width, double height, char *err,
                   size_t errlen)
{
    memset(c, 0, sizeof *c);
    if (ends_with(path, ".png"))
        c->png = 1;
    else if (!ends_with(path, ".svg")) {
        snprintf(err, errlen, "%s: the picture's format comes from its extension, .svg or .png",
                 path);
        return -1;
    }
    size_t n = strlen(path) + 32;
    c->tmp = malloc(n);
    c->path = strdup(path);
    if (!c->tmp || !c->path) {
        pk_canvas_abort(c);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    snprintf(c->tmp, n, "%s.tmp.%ld", path, (long)getpid());
    c->surface = c->png
        ? cairo_image_surface_create(CAIRO_FORMAT_RGB24, (int)ceil(width), (int)ceil(height))
        : cairo_svg_surface_create(c->tmp, width, height);
    if (cairo_surface_status(c->surface) != CAIRO_STATUS_SUCCESS) {
        snprintf(err, errlen, "cannot create %s: %s", c->tmp,
                 cairo_status_to_string(cairo_surface_status(c->surface)));
        pk_canvas_abort(c);
        return -1;
    }
    c->cr = cairo_create(c->surface);
    cairo_set_source_rgb(c->cr, 1, 1, 1);
    cairo_paint(c->cr);
    return 0;
}

int pk_canvas_finish(pk_canvas *c, char *err, size_t errlen)
{
    cairo_status_t st = cairo_status(c->cr);
    cairo_destroy(c->cr);
    c->cr = NULL;
    if (st == CAIRO_STATUS_SUCCESS && c->png)
        st = cairo_surface_write_to_png(c->surface, c->tmp);
    cairo_surface_finish(c->surface);
    if (st == CAIRO_STATUS_SUCCESS)
        st = cairo_surface_status(c->surface);
    cairo_surface_destroy(c->surface);
    c->surface = NULL;
    int rc = 0;
    if (st != CAIRO_STATUS_SUCCESS || rename(c->tmp, c->path) != 0) {
        snprintf(err, errlen, "cannot write %s: %s", c->path,
                 st != CAIRO_STATUS_SUCCESS ? cairo_status_to_string(st) : "rename failed");
        unlink(c->tmp);
        rc = -1;
    }
    free(c->tmp);
    free(c->path);
    c->tmp = c->path = NULL;
    return rc;
}

void pk_canvas_abort(pk_canvas *c)
{
    if (c->cr)
        cairo_destroy(c->cr);
    if (c->surface) {
        cairo_surface_finish(c->surface);
        cairo_surface_destroy(c->surface);
    }
    if (c->tmp)
        unlink(c->tmp);
    free(c->tmp);
    free(c->path);
    memset(c, 0, sizeof *c);
}

void pk_canvas_class_colour(cairo_t *cr, int species, int classes, double shade)
{
    /* viridis at 5 stops, interpolated */
    static const double stop[5][3] = {{0.267, 0.005, 0.329},
                                      {0.231, 0.322, 0.545},
                                      {0.129, 0.569, 0.549},
                                      {0.369, 0.788, 0.384},
                                      {0.993, 0.906, 0.144}};
    double t = classes > 1 ? (double)species / (double)(classes - 1) : 0.5;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double u = t * 4;
    int k = u >= 4 ? 3 : (int)u;
    double f = u - k, rgb[3];
    for (int i = 0; i < 3; i++)
        rgb[i] = shade * (stop[k][i] + f * (stop[k + 1][i] - stop[k][i]));
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
}

void pk_canvas_text(cairo_t *cr, double x, double y, double ax, double ay, double size,
                    const char *text)
{
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, text, &e);
    cairo_move_to(cr, x - ax * e.width - e.x_bearing, y - ay * e.height - e.y_bearing);
    cairo_show_text(cr, text);
}
