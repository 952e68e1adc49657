/* picture_fe2.c — the response of an fe2 result (picture.h): the reaction of
 * every displacement condition in its prescribed component (f_v of Meier
 * 2009 Fig. 6.2 is the bottom support's) and the dilatancy Δ = (v/V − 1)·100 %
 * of the specimen (right axis) over the load steps. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "picture_canvas.h"
#include "picture_internal.h"
#include "plot_axes.h"
#include "plot_data.h"

#define W 760.0
#define H 480.0
#define FE2 "/observables/fe2/"
#define MAXC 8

int pk_picture_response(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    size_t n, nd, nc, m;
    double *t = pk_plot_series(f, FE2 "load_steps/time", &n);
    double *dil = pk_plot_series(f, FE2 "dilatancy_percent/value", &nd);
    double *comp = pk_plot_series(f, FE2 "reaction/component", &nc);
    char *names = pk_plot_text(f, FE2 "reaction/names");
    char bc[64], unit[32];
    pk_plot_string(f, FE2 "boundary_condition", bc, sizeof bc);
    pk_plot_unit(f, FE2 "reaction", unit, sizeof unit);
    double *re[MAXC] = {0};
    char label[MAXC][80];
    int nre = 0;
    const char *name = names ? names : "";
    for (size_t b = 0; t && comp && b < nc && nre < MAXC; b++) {
        size_t len = strcspn(name, "\n");
        if (comp[b] >= 0) {
            re[nre] = pk_plot_tensor(f, FE2 "reaction/value", (int)b, (int)comp[b], &m);
            if (re[nre] && m == n) {
                snprintf(label[nre], sizeof label[0], "%.*s (%c)", (int)len, name,
                         comp[b] ? 'y' : 'x');
                nre++;
            } else
                free(re[nre]), re[nre] = NULL;
        }
        name += len + (name[len] == '\n');
    }
    pk_plot_file_close(f);
    int rc = -1;
    pk_canvas c;
    if (!t || n < 1 || !dil || nd != n) {
        snprintf(err, errlen,
                 "%s has no fe2 response (only fe2 results have /observables/fe2/load_steps)",
                 h5_path);
    } else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        static const pk_plot_style pal[MAXC] = {
            {0.13, 0.4, 0.7, 2, 0, 1}, {0.2, 0.6, 0.2, 2, 0, 1},   {0.55, 0.3, 0.65, 2, 0, 1},
            {0.6, 0.45, 0.1, 2, 0, 1}, {0.9, 0.45, 0.7, 2, 0, 1},  {0.4, 0.4, 0.4, 2, 0, 1},
            {0.1, 0.7, 0.75, 2, 0, 1}, {0.75, 0.75, 0.15, 2, 0, 1}};
        const pk_plot_style sd = {0.85, 0.33, 0.1, 2, 1, 1};
        double lo, hi, ylo = INFINITY, yhi = -INFINITY;
        for (int k = 0; k < nre; k++)
            if (pk_plot_range(re[k], n, 0, &lo, &hi))
                ylo = fmin(ylo, lo), yhi = fmax(yhi, hi);
        if (!(ylo <= yhi))
            ylo = yhi = 0;
        pk_plot p = {.left = 80, .top = 50, .right = W - 90, .bottom = H - 60};
        pk_plot_range(t, n, 0, &lo, &hi);
        pk_plot_axis_fit(&p.x, fmin(lo, 0), hi, 0);
        pk_plot_axis_fit(&p.y, fmin(ylo, 0), fmax(yhi, 0), 0);
        pk_plot q = p; /* the dilatancy on the right */
        if (!pk_plot_range(dil, n, 0, &lo, &hi))
            lo = hi = 0;
        pk_plot_axis_fit(&q.y, fmin(lo, 0), fmax(hi, 0), 0);
        pk_plot_grid_y(c.cr, &p, 0);
        pk_plot_grid_y(c.cr, &q, 1);
        pk_plot_grid_x(c.cr, &p);
        pk_plot_frame(c.cr, &p, "load (stage + fraction of the stage)", NULL);
        char ytitle[96];
        snprintf(ytitle, sizeof ytitle, "reaction of the support per unit thickness%s%s%s",
                 unit[0] ? " [" : "", unit, unit[0] ? "]" : "");
        pk_plot_title_y(c.cr, &p, 0, ytitle, NULL, NULL);
        pk_plot_title_y(c.cr, &q, 1, "dilatancy \u0394 (%)", NULL, &sd);
        const pk_plot_style *styles[MAXC + 1];
        const char *texts[MAXC + 1];
        for (int k = 0; k < nre; k++) {
            pk_plot_line(c.cr, &p, t, re[k], n, &pal[k]);
            styles[k] = &pal[k];
            texts[k] = label[k];
        }
        pk_plot_line(c.cr, &q, t, dil, n, &sd);
        styles[nre] = &sd;
        texts[nre] = "dilatancy (right axis)";
        /* the corner the curves leave freest, the dilatancy mapped onto the left axis */
        double *dil_on_p = malloc(n * sizeof *dil_on_p);
        const double *ys[MAXC + 1];
        for (int k = 0; k < nre; k++)
            ys[k] = re[k];
        for (size_t i = 0; dil_on_p && i < n; i++)
            dil_on_p[i] = p.y.lo + (dil[i] - q.y.lo) / (q.y.hi - q.y.lo) * (p.y.hi - p.y.lo);
        ys[nre] = dil_on_p ? dil_on_p : dil;
        int corner = pk_plot_free_corner(c.cr, &p, texts, nre + 1, t, ys, nre + 1, n);
        free(dil_on_p);
        pk_plot_legend(c.cr, &p, corner, styles, texts, nre + 1);
        char text[200];
        snprintf(text, sizeof text, "FE\u00b2 response: %s boundary condition, %zu load step%s",
                 *bc ? bc : "unknown", n, n == 1 ? "" : "s");
        pk_plot_heading(c.cr, &p, text);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    for (int k = 0; k < MAXC; k++)
        free(re[k]);
    free(t);
    free(dil);
    free(comp);
    free(names);
    return rc;
}
