/* picture_history.c — a placer's run over its events (a placer with a
 * history, pack_placer.h: EDMD): φ on the left axis, the reduced pressure
 * PV/NkT on a logarithmic right axis (picture.h).  The data sit under
 * /observables/<algorithm>/, the algorithm named by /observables/algorithm. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "picture_canvas.h"
#include "picture_internal.h"
#include "plot_axes.h"
#include "plot_data.h"

#define W 760.0
#define H 480.0

int pk_picture_history(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    size_t n, np, nz;
    char alg[32] = "", at[128];
    pk_plot_string(f, "/observables/algorithm", alg, sizeof alg);
#define AT(name) (snprintf(at, sizeof at, "/observables/%s/%s", alg, name), at)
    /* the events: the H5MD step of the history (a flat `events` series in
     * files before the H5MD 1.1 layout) */
    double *ev = pk_plot_series(f, AT("history/phi/step"), &n);
    if (!ev)
        ev = pk_plot_series(f, AT("history/events"), &n);
    double *phi = pk_plot_series(f, AT("history/phi"), &np);
    double *z = pk_plot_series(f, AT("history/reduced_pressure"), &nz);
    double phi_final = pk_plot_scalar(f, AT("phi_final"));
    double z_final = pk_plot_scalar(f, AT("reduced_pressure"));
    double events = pk_plot_scalar(f, AT("events"));
    char criterion[64];
    pk_plot_string(f, AT("termination_criterion"), criterion, sizeof criterion);
#undef AT
    pk_plot_file_close(f);
    int rc = -1;
    double lo, hi;
    pk_canvas c;
    if (!ev || !phi || !z || n < 2 || np != n || nz != n) {
        snprintf(err, errlen,
                 "%s has no placer history (only pack results of a placer with one, "
                 "EDMD, have /observables/<algorithm>/history)",
                 h5_path);
    } else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        pk_plot p = {.left = 80, .top = 50, .right = W - 90, .bottom = H - 60};
        pk_plot_range(ev, n, 0, &lo, &hi);
        pk_plot_axis_fit(&p.x, lo, hi, 0);
        pk_plot_range(phi, n, 0, &lo, &hi);
        pk_plot_axis_fit(&p.y, lo, hi, 0);
        pk_plot q = p; /* the pressure's axis on the right */
        if (!pk_plot_range(z, n, 1, &lo, &hi))
            lo = hi = 1;
        pk_plot_axis_fit(&q.y, lo, hi, 1);
        const pk_plot_style s_phi = {0.13, 0.4, 0.7, 2, 0, 0}, s_z = {0.85, 0.33, 0.1, 2, 0, 0};
        pk_plot_grid_y(c.cr, &p, 0);
        pk_plot_grid_y(c.cr, &q, 1);
        pk_plot_grid_x(c.cr, &p);
        pk_plot_frame(c.cr, &p, "events", NULL);
        pk_plot_title_y(c.cr, &p, 0, "packing fraction \u03c6", NULL, &s_phi);
        pk_plot_title_y(c.cr, &q, 1, "reduced pressure PV/NkT (log scale)", NULL, &s_z);
        pk_plot_line(c.cr, &p, ev, phi, n, &s_phi);
        pk_plot_line(c.cr, &q, ev, z, n, &s_z);
        const pk_plot_style *styles[] = {&s_phi, &s_z};
        const char *texts[] = {"\u03c6 (left axis)", "reduced pressure (right axis, log)"};
        pk_plot_legend(c.cr, &p, 3, styles, texts, 2);
        char text[200];
        snprintf(
            text, sizeof text, "EDMD: \u03c6 = %.4f, reduced pressure %.3g after %.0f events%s%s",
            isfinite(phi_final) ? phi_final : phi[n - 1], isfinite(z_final) ? z_final : z[n - 1],
            isfinite(events) ? events : ev[n - 1], *criterion ? ", stop: " : "", criterion);
        pk_plot_heading(c.cr, &p, text);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    free(ev);
    free(phi);
    free(z);
    return rc;
}
