/* picture_canvas.h — a cairo drawing surface that ends as an SVG or PNG file,
 * and the colours every picture shares. */
#ifndef PK_PICTURE_CANVAS_H
#define PK_PICTURE_CANVAS_H

#include <cairo.h>
#include <stddef.h>

typedef struct pk_canvas {
    cairo_surface_t *surface;
    cairo_t *cr;
    int png; /* 1: PNG written at finish; 0: SVG streamed to tmp */
    char *tmp, *path;
} pk_canvas;

/* A width × height (pt for SVG, px for PNG) canvas for path (.svg or .png),
 * white background.  0 on success, -1 with err. */
int pk_canvas_open(pk_canvas *c, const char *path, double width, double height, char *err,
                   size_t errlen);
/* Write the file into place; frees the canvas.  0 on success, -1 with err. */
int pk_canvas_finish(pk_canvas *c, char *err, size_t errlen);
/* Discard the canvas and its temporary file. */
void pk_canvas_abort(pk_canvas *c);

/* Fill colour of size class `species` of `classes` (coarse = dark blue →
 * fine = yellow, a viridis-like ramp), scaled by `shade` in [0, 1]. */
void pk_canvas_class_colour(cairo_t *cr, int species, int classes, double shade);

/* Text at (x, y) anchored by (ax, ay) in [0, 1] of its extent (0,0 = left,
 * baseline-top; 0.5 = centred). */
void pk_canvas_text(cairo_t *cr, double x, double y, double ax, double ay, double size,
                    const char *text);

#endif
