/* picture_homog.c — the plots of a homogenize result: the stress–strain
 * curve (every non-zero component of P̄ over the F̄ component the load
 * varies most; the labels write them P and F, the toy text API draws no
 * combining macron) and the relaxation residual of every load step (picture.h). */
#include <jansson.h>
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
#define HOMOG "/observables/homogenize/"

/* The subscript digit a + 1 in UTF-8. */
static const char *sub(int a)
{
    static const char *const s[] = {"\u2081", "\u2082", "\u2083"};
    return s[a];
}

/* "periodic boundary condition, uniaxial_compression, 20 steps": the
 * setting the plots of one result share (the load from the job stored in
 * /parameters/job). */
static void setting(hid_t f, size_t steps, char *out, size_t n)
{
    char bc[64], load[64] = "";
    pk_plot_string(f, HOMOG "boundary_condition", bc, sizeof bc);
    char *job = pk_plot_text(f, "/parameters/job");
    json_t *j = job ? json_loads(job, 0, NULL) : NULL;
    const char *type = json_string_value(
        json_object_get(json_object_get(json_object_get(j, "inputs"), "load"), "type"));
    if (type)
        snprintf(load, sizeof load, ", load %s", type);
    json_decref(j);
    free(job);
    snprintf(out, n, "%s boundary condition%s, %zu step%s", *bc ? bc : "unknown", load, steps,
             steps == 1 ? "" : "s");
}

static const pk_plot_style palette[9] = {
    {0.13, 0.4, 0.7, 2, 0, 1},  {0.85, 0.33, 0.1, 2, 0, 1},  {0.2, 0.6, 0.2, 2, 0, 1},
    {0.55, 0.3, 0.65, 2, 0, 1}, {0.6, 0.45, 0.1, 2, 0, 1},   {0.9, 0.45, 0.7, 2, 0, 1},
    {0.4, 0.4, 0.4, 2, 0, 1},   {0.75, 0.75, 0.15, 2, 0, 1}, {0.1, 0.7, 0.75, 2, 0, 1},
};

int pk_picture_stress(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    size_t n = 0, m;
    double *F[9] = {0}, *P[9] = {0};
    double *probe = pk_plot_tensor(f, HOMOG "F", 2, 2, &m);
    int dim = probe ? 3 : 2, ok = 1;
    free(probe);
    for (int k = 0; k < dim * dim; k++) {
        F[k] = pk_plot_tensor(f, HOMOG "F", k / dim, k % dim, &m);
        if (k == 0)
            n = m;
        ok = ok && F[k] && m == n;
        P[k] = pk_plot_tensor(f, HOMOG "P", k / dim, k % dim, &m);
        ok = ok && P[k] && m == n;
    }
    char unit[32], where[160];
    pk_plot_unit(f, HOMOG "P/11", unit, sizeof unit);
    if (!*unit)
        pk_plot_unit(f, HOMOG "P", unit, sizeof unit);
    setting(f, n, where, sizeof where);
    pk_plot_file_close(f);
    int rc = -1;
    pk_canvas c;
    if (!ok || n < 1) {
        snprintf(err, errlen,
                 "%s has no stress-strain data (only homogenize results have "
                 "/observables/homogenize/F and P)",
                 h5_path);
    } else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        /* the x axis: the F̄ component the load varies most */
        int kx = 0;
        double range = -1, lo, hi, plo = INFINITY, phi = -INFINITY, big = 0;
        for (int k = 0; k < dim * dim; k++) {
            if (pk_plot_range(F[k], n, 0, &lo, &hi) && hi - lo > range) {
                range = hi - lo;
                kx = k;
            }
            if (pk_plot_range(P[k], n, 0, &lo, &hi)) {
                plo = fmin(plo, lo);
                phi = fmax(phi, hi);
                big = fmax(big, fmax(fabs(lo), fabs(hi)));
            }
        }
        pk_plot p = {.left = 80, .top = 50, .right = W - 30, .bottom = H - 60};
        pk_plot_range(F[kx], n, 0, &lo, &hi);
        pk_plot_axis_fit(&p.x, lo, hi, 0);
        pk_plot_axis_fit(&p.y, plo, phi, 0);
        pk_plot_grid_y(c.cr, &p, 0);
        pk_plot_grid_x(c.cr, &p);
        char xname[64];
        snprintf(xname, sizeof xname, "deformation gradient F%s%s", sub(kx / dim), sub(kx % dim));
        pk_plot_frame(c.cr, &p, xname, NULL);
        pk_plot_title_y(c.cr, &p, 0, "first Piola stress P (RVE average)", unit, NULL);
        const pk_plot_style *styles[9];
        const double *ys[9];
        char names[9][32];
        const char *texts[9];
        int shown = 0;
        for (int k = 0; k < dim * dim; k++) {
            if (!pk_plot_range(P[k], n, 0, &lo, &hi) || fmax(fabs(lo), fabs(hi)) <= 1e-9 * big)
                continue; /* a component that stays zero */
            styles[shown] = &palette[k];
            ys[shown] = P[k];
            snprintf(names[shown], sizeof names[shown], "P%s%s", sub(k / dim), sub(k % dim));
            texts[shown] = names[shown];
            pk_plot_line(c.cr, &p, F[kx], P[k], n, &palette[k]);
            shown++;
        }
        if (shown)
            pk_plot_legend(c.cr, &p,
                           pk_plot_free_corner(c.cr, &p, texts, shown, F[kx], ys, shown, n), styles,
                           texts, shown);
        char text[240];
        snprintf(text, sizeof text, "Stress-strain: %s", where);
        pk_plot_heading(c.cr, &p, text);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    for (int k = 0; k < 9; k++) {
        free(F[k]);
        free(P[k]);
    }
    return rc;
}

int pk_picture_residual(const char *h5_path, const char *out_path, char *err, size_t errlen)
{
    hid_t f = pk_plot_file_open(h5_path);
    if (f < 0) {
        snprintf(err, errlen, "cannot open %s as an HDF5 file", h5_path);
        return -1;
    }
    size_t n, n0, nr, ns;
    double *res = pk_plot_series(f, HOMOG "dr/residual", &n);
    double *res0 = pk_plot_series(f, HOMOG "dr/residual_initial", &n0);
    double *ratio = pk_plot_series(f, "/observables/audit/residual_ratio", &nr);
    double *stop = pk_plot_series(f, HOMOG "dr/stop_code", &ns);
    char unit[32], where[160];
    pk_plot_unit(f, HOMOG "dr/residual", unit, sizeof unit);
    setting(f, n, where, sizeof where);
    pk_plot_file_close(f);
    int rc = -1;
    pk_canvas c;
    double *step = res && n0 == n && n ? malloc(3 * n * sizeof *step) : NULL;
    if (!res || !res0 || n0 != n || n < 1) {
        snprintf(err, errlen,
                 "%s has no residual history (only homogenize results have "
                 "/observables/homogenize/dr/residual)",
                 h5_path);
    } else if (!step) {
        snprintf(err, errlen, "out of memory");
    } else if (pk_canvas_open(&c, out_path, W, H, err, errlen) == 0) {
        /* the audit's residual_ratio is final ‖f‖ / target, one per recorded step */
        double *target = step + n, *failed = step + 2 * n;
        int has_target = ratio && nr >= n, has_failed = 0;
        for (size_t k = 0; k < n; k++) {
            step[k] = (double)(k + 1);
            target[k] = has_target && ratio[k] > 0 ? res[k] / ratio[k] : NAN;
            /* dr/stop_code 3 max_iter, 4 cancelled, 5 wall_time: not converged */
            failed[k] = stop && ns == n && stop[k] >= 3 ? res[k] : NAN;
            has_failed |= isfinite(failed[k]);
        }
        double lo, hi, lo2, hi2;
        pk_plot p = {.left = 80, .top = 50, .right = W - 30, .bottom = H - 60};
        p.x.integer = 1;
        pk_plot_axis_fit(&p.x, n > 1 ? 1 : 0, (double)n, 0);
        if (!pk_plot_range(res, n, 1, &lo, &hi))
            lo = hi = 1;
        if (pk_plot_range(res0, n, 1, &lo2, &hi2))
            lo = fmin(lo, lo2), hi = fmax(hi, hi2);
        if (has_target && pk_plot_range(target, n, 1, &lo2, &hi2))
            lo = fmin(lo, lo2), hi = fmax(hi, hi2);
        pk_plot_axis_fit(&p.y, lo, hi, 1);
        pk_plot_grid_y(c.cr, &p, 0);
        pk_plot_grid_x(c.cr, &p);
        pk_plot_frame(c.cr, &p, "load step", NULL);
        pk_plot_title_y(c.cr, &p, 0, "|f| of the free degrees of freedom (log scale)", unit, NULL);
        const pk_plot_style s0 = {0.55, 0.55, 0.55, 1.5, 0, 1}, s1 = {0.13, 0.4, 0.7, 2, 0, 1},
                            st = {0, 0, 0, 1, 1, 0}, sf = {0.85, 0.1, 0.1, 2, 0, 2};
        const pk_plot_style *styles[4] = {&s0, &s1};
        const char *texts[4] = {"at the start of the step", "relaxed (final)"};
        const double *ys[2] = {res0, res};
        int rows = 2;
        pk_plot_line(c.cr, &p, step, res0, n, &s0);
        pk_plot_line(c.cr, &p, step, res, n, &s1);
        if (has_target) { /* over the relaxed residual: relaxation stops just below it */
            pk_plot_line(c.cr, &p, step, target, n, &st);
            styles[rows] = &st;
            texts[rows++] = "target of the relaxation";
        }
        if (has_failed) {
            pk_plot_line(c.cr, &p, step, failed, n, &sf);
            styles[rows] = &sf;
            texts[rows++] = "not converged";
        }
        pk_plot_legend(c.cr, &p, pk_plot_free_corner(c.cr, &p, texts, rows, step, ys, 2, n), styles,
                       texts, rows);
        char text[240];
        snprintf(text, sizeof text, "Relaxation residual per step: %s", where);
        pk_plot_heading(c.cr, &p, text);
        rc = pk_canvas_finish(&c, err, errlen);
    }
    free(step);
    free(res);
    free(res0);
    free(ratio);
    free(stop);
    return rc;
}
