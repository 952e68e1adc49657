/* dem_rattler.c — rattler removal (Meier 2009 §4.3.5, Table 4.3) by the
 * positive-spanning test of each free grain's contacts; contract: dem_rattler.h. */
#include "dem_rattler.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* All directions lie in the closed half-space {u·n >= 0}?  (tolerant) */
static int in_half_space(const double *u, const double *n, size_t m, double tol)
{
    double uu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(uu > 1e-12))
        return 0;
    for (size_t k = 0; k < m; k++) {
        const double *v = &n[3 * k];
        if ((u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / uu < -tol)
            return 0;
    }
    return 1;
}

/* If the directions lie in some closed half-space, one whose boundary passes
 * through dim−1 of them (or whose normal is ⊥ their span) exists: an extreme
 * ray of the polyhedral cone {u : u·n_k >= 0} has dim−1 active constraints.
 * So it suffices to test u = ±Ω n_a in 2D and u = ±n_a × n_b in 3D. */
int pk_dem_positively_spanning(const double *n, size_t m, int dim, double tol)
{
    if (m < (size_t)dim + 1)
        return 0;
    int any = 0;
    for (size_t a = 0; a < m; a++) {
        const double *p = &n[3 * a];
        if (dim == 2) {
            double u[3] = {-p[1], p[0], 0}, w[3] = {p[1], -p[0], 0};
            if (in_half_space(u, n, m, tol) || in_half_space(w, n, m, tol))
                return 0;
            any = 1;
            continue;
        }
        for (size_t b = a + 1; b < m; b++) {
            const double *q = &n[3 * b];
            double u[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2],
                           p[0] * q[1] - p[1] * q[0]};
            if (sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) < 1e-9)
                continue;
            double w[3] = {-u[0], -u[1], -u[2]};
            if (in_half_space(u, n, m, tol) || in_half_space(w, n, m, tol))
                return 0;
            any = 1;
        }
    }
    return any; /* all directions collinear: not spanning */
}

size_t pk_dem_rattlers(const pk_dem_pairs *c, int dim, size_t np, const uint8_t *is_free,
                       uint8_t *rattler)
{
    memset(rattler, 0, np);
    /* adjacency (CSR) of the contacts */
    size_t *start = calloc(np + 1, sizeof *start);
    size_t nc = 0;
    if (!start)
        return (size_t)-1;
    for (size_t p = 0; p < c->n; p++)
        if (c->eps[p] >= 0 && c->len[p] > 0) {
            start[c->i[p] + 1]++;
            start[c->j[p] + 1]++;
            nc++;
        }
    for (size_t i = 0; i < np; i++)
        start[i + 1] += start[i];
    size_t *fill = malloc((np + 1) * sizeof *fill);
    size_t *adj = malloc((2 * nc + 1) * sizeof *adj); /* pair index */
    size_t maxdeg = 0;
    for (size_t i = 0; i < np; i++)
        if (start[i + 1] - start[i] > maxdeg)
            maxdeg = start[i + 1] - start[i];
    double *dirs = malloc(3 * (maxdeg + 1) * sizeof *dirs);
    if (!fill || !adj || !dirs) {
        free(start);
        free(fill);
        free(adj);
        free(dirs);
        return (size_t)-1;
    }
    memcpy(fill, start, (np + 1) * sizeof *fill);
    for (size_t p = 0; p < c->n; p++)
        if (c->eps[p] >= 0 && c->len[p] > 0) {
            adj[fill[c->i[p]]++] = p;
            adj[fill[c->j[p]]++] = p;
        }
    /* Table 4.3: sweep until no new rattler.  A grain's test can change only
     * when one of its neighbours became a rattler since its last test, so a
     * sweep tests only those (dirty) grains, in the same ascending order —
     * the sweeps of testing every grain, with the same outcome
     * (tests/unit/test_dem_rattlers.c). */
    uint8_t *dirty = (uint8_t *)fill; /* reused: one byte per grain */
    for (size_t i = 0; i < np; i++)
        dirty[i] = is_free[i] != 0;
    size_t count = 0;
    int repeat = 1;
    while (repeat) {
        repeat = 0;
        for (size_t i = 0; i < np; i++) {
            if (!dirty[i])
                continue;
            dirty[i] = 0;
            size_t m = 0;
            for (size_t e = start[i]; e < start[i + 1]; e++) {
                size_t p = adj[e];
                size_t other = (size_t)c->i[p] == i ? (size_t)c->j[p] : (size_t)c->i[p];
                if (rattler[other])
                    continue;
                double s = (size_t)c->i[p] == i ? 1.0 : -1.0; /* direction from i to other */
                for (int k = 0; k < 3; k++)
                    dirs[3 * m + k] = k < dim ? s * c->l[3 * p + k] / c->len[p] : 0;
                m++;
            }
            if (!pk_dem_positively_spanning(dirs, m, dim, 1e-9)) {
                rattler[i] = 1;
                count++;
                repeat = 1;
                for (size_t e = start[i]; e < start[i + 1]; e++) {
                    size_t p = adj[e];
                    size_t other = (size_t)c->i[p] == i ? (size_t)c->j[p] : (size_t)c->i[p];
                    dirty[other] = is_free[other] && !rattler[other];
                }
            }
        }
    }
    free(start);
    free(fill);
    free(adj);
    free(dirs);
    return count;
}
