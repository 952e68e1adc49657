/* picture_grading.c — the grading curve of a pack result, target against
 * achieved (picture.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "picture_canvas.h"
#include "picture_internal.h"
#include "plot_axes.h"
#include "plot_data.h"

#define W 720.0
#define H 480.0

int pk_picture_grading(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    size_t n, nt, na;
    double *d = pk_plot_series(f, "/observables/grading/sieve_size", &n);
    double *pt = pk_plot_series(f, "/observables/grading/target_passing_percent", &nt);
    double *pa = pk_plot_series(f, "/observables/grading/achieved_passing_percent", &na);
    char unit[32];
    pk_plot_unit(f, "/observables/grading/sieve_size", unit, sizeof unit);
    double phi_mix = pk_plot_scalar(f, "/observables/phi_mix");
    double phi_eff = pk_plot_scalar(f, "/observables/phi_resolved");
    pk_plot_file_close(f);
    double lo, hi;
    int rc = -1;
    pk_canvas c;
    if (!d || !pt || !pa || n < 2 || nt != n || na != n || !pk_plot_range(d, n, 1, &lo, &hi) ||
        !(hi > lo)) {
        snprintf(err, errlen, "%s has no grading curve (only pack results do)", h5_path);
    } else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        pk_plot p = {.left = 70, .top = 50, .right = W - 30, .bottom = H - 60};
        /* the sieve range to a tenth of a decade */
        p.x = (pk_plot_axis){.lo = pow(10, floor(log10(lo) * 10) / 10),
                             .hi = pow(10, ceil(log10(hi) * 10) / 10),
                             .log = 1};
        pk_plot_axis_fit(&p.y, 0, 100, 0);
        pk_plot_grid_y(c.cr, &p, 0);
        pk_plot_grid_x(c.cr, &p);
        pk_plot_frame(c.cr, &p, "sieve size", *unit ? unit : "-");
        pk_plot_title_y(c.cr, &p, 0, "passing", "%", NULL);
        const pk_plot_style target = {0.2, 0.2, 0.2, 2, 0, 0},
                            achieved = {0.85, 0.33, 0.1, 2, 0, 1};
        pk_plot_line(c.cr, &p, d, pt, n, &target);
        pk_plot_line(c.cr, &p, d, pa, n, &achieved);
        char text[160];
        snprintf(
            text, sizeof text,
            "\u03c6_M = %.2f %%, \u03c6_eff = %.2f %% (grains finer than d_min are left to the "
            "matrix)",
            100 * phi_mix, 100 * phi_eff);
        pk_plot_heading(c.cr, &p, text);
        const pk_plot_style *styles[] = {&target, &achieved};
        const char *texts[] = {"target (the job's grading, resolved part)",
                               "achieved (placed grains)"};
        pk_plot_legend(c.cr, &p, 0, styles, texts, 2);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    free(d);
    free(pt);
    free(pa);
    return rc;
}
