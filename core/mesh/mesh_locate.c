/* mesh_locate.c — point-in-mesh and distance to the mesh boundary through
 * two core/space/grid.h grids.  Contract: core/mesh/mesh_locate.h. */
#include "mesh_locate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void sub(const double *a, const double *b, double *o)
{
    for (int k = 0; k < 3; k++)
        o[k] = a[k] - b[k];
}

void pk_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                            const double c[3], double q[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    sub(b, a, ab);
    sub(c, a, ac);
    sub(p, a, ap);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(q, a, 3 * sizeof *q);
        return;
    }
    sub(p, b, bp);
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(q, b, 3 * sizeof *q);
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + v * ab[k];
        return;
    }
    sub(p, c, cp);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(q, c, 3 * sizeof *q);
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + w * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            q[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int k = 0; k < 3; k++)
        q[k] = a[k] + ab[k] * v + ac[k] * w;
}

/* Bounding sphere (centroid, farthest vertex) of nv nodes of the mesh. */
static double bound(const pk_mesh *m, const int32_t *v, int nv, double c[3])
{
    c[0] = c[1] = c[2] = 0;
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++)
            c[k] += m->x[3 * (size_t)v[i] + k] / nv;
    double r2 = 0;
    for (int i = 0; i < nv; i++) {
        double d[3];
        sub(&m->x[3 * (size_t)v[i]], c, d);
        r2 = fmax(r2, dot(d, d));
    }
    return sqrt(r2) * (1 + 1e-12);
}

static int fill_grid(pk_mesh_locator *L, pk_particles *b, pk_grid *g, const int32_t *v, int nv,
                     size_t n)
{
    if (pk_particles_init(b, 3, n ? n : 1) != 0)
        return -1;
    double rmin = INFINITY, rmax = 0;
    for (size_t i = 0; i < n; i++) {
        double c[3], r = bound(L->m, &v[(size_t)nv * i], nv, c);
        pk_particles_push(b, c, r, 0);
        rmin = fmin(rmin, r);
        rmax = fmax(rmax, r);
    }
    if (!(rmax > 0))
        rmin = rmax = 1;
    if (pk_grid_init(g, &L->box, rmin, rmax, 0, n ? n : 1) != 0)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (pk_grid_insert(g, b, i) != 0)
            return -1;
    return 0;
}

int pk_mesh_locator_init(pk_mesh_locator *L, const pk_mesh *m)
{
    memset(L, 0, sizeof *L);
    L->m = m;
    L->box.dim = 3;
    double span = 0;
    for (int k = 0; k < 3; k++)
        span = fmax(span, m->hi[k]);
    for (int k = 0; k < 3; k++)
        L->box.L[k] = fmax(m->hi[k], 1e-9 * span) * (1 + 1e-12);
    L->fn = malloc((m->nbface ? m->nbface : 1) * 3 * sizeof *L->fn);
    if (!L->fn || fill_grid(L, &L->tb, &L->tg, m->t, 4, m->ntet) != 0 ||
        fill_grid(L, &L->fb, &L->fg, m->bface, 3, m->nbface) != 0) {
        pk_mesh_locator_free(L);
        return -1;
    }
    for (size_t f = 0; f < m->nbface; f++) {
        const double *a = &m->x[3 * (size_t)m->bface[3 * f]],
                     *b = &m->x[3 * (size_t)m->bface[3 * f + 1]],
                     *c = &m->x[3 * (size_t)m->bface[3 * f + 2]];
        double u[3], w[3], *n = &L->fn[3 * f];
        sub(b, a, u);
        sub(c, a, w);
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        double l = sqrt(dot(n, n));
        for (int k = 0; k < 3; k++)
            n[k] /= l;
    }
    return 0;
}

void pk_mesh_locator_free(pk_mesh_locator *L)
{
    pk_grid_free(&L->tg);
    pk_grid_free(&L->fg);
    pk_particles_free(&L->tb);
    pk_particles_free(&L->fb);
    free(L->fn);
    memset(L, 0, sizeof *L);
}

typedef struct locate_ctx {
    const pk_mesh *m;
    const double *x;
    long found;
} locate_ctx;

static int visit_tet(size_t e, const double dx[PK_MAXDIM], double dist2, void *vctx)
{
    (void)dx;
    (void)dist2;
    locate_ctx *c = vctx;
    const pk_mesh *m = c->m;
    const int32_t *t = &m->t[4 * e];
    /* barycentric coordinates by sub-volumes (Jerier's tets are positive) */
    double V = pk_mesh_tet_volume(m, e);
    static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    for (int k = 0; k < 4; k++) {
        const double *a = &m->x[3 * (size_t)t[kFace[k][0]]], *b = &m->x[3 * (size_t)t[kFace[k][1]]],
                     *cc = &m->x[3 * (size_t)t[kFace[k][2]]];
        double u[3], v[3], w[3];
        sub(b, a, u);
        sub(cc, a, v);
        sub(c->x, a, w);
        /* volume of (face, x) on the inner side: x inside ⇔ all four >= 0 */
        double s = -(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                     u[2] * (v[0] * w[1] - v[1] * w[0])) /
            6;
        if (s < -1e-12 * V)
            return 0;
    }
    c->found = (long)e;
    return 1;
}

long pk_mesh_locate(const pk_mesh_locator *L, const double x[3])
{
    locate_ctx c = {L->m, x, -1};
    pk_grid_query(&L->tg, &L->tb, x, 0, 0, visit_tet, &c);
    return c.found;
}

typedef struct near_ctx {
    const pk_mesh_locator *L;
    const double *x;
    double reach;
    int max, n;
    double (*q)[3], (*nn)[3], *d;
} near_ctx;

static void face_closest(const pk_mesh_locator *L, size_t f, const double *x, double q[3])
{
    const pk_mesh *m = L->m;
    pk_closest_on_triangle(x, &m->x[3 * (size_t)m->bface[3 * f]],
                           &m->x[3 * (size_t)m->bface[3 * f + 1]],
                           &m->x[3 * (size_t)m->bface[3 * f + 2]], q);
}

static int visit_face(size_t f, const double dx[PK_MAXDIM], double dist2, void *vctx)
{
    (void)dx;
    (void)dist2;
    near_ctx *c = vctx;
    double q[3], d[3];
    face_closest(c->L, f, c->x, q);
    sub(c->x, q, d);
    double dist = sqrt(dot(d, d));
    if (!(dist < c->reach))
        return 0;
    const double *n = &c->L->fn[3 * f];
    /* same plane as one already listed? keep the nearer point */
    for (int i = 0; i < c->n; i++) {
        double dq[3];
        sub(q, c->q[i], dq);
        if (dot(n, c->nn[i]) > 1 - 1e-9 && fabs(dot(dq, n)) <= 1e-9 * (1 + dist + c->d[i])) {
            if (dist < c->d[i]) {
                memcpy(c->q[i], q, sizeof q);
                c->d[i] = dist;
            }
            return 0;
        }
    }
    /* insert sorted by distance, dropping the farthest when full */
    if (c->n == c->max && c->d[c->max - 1] <= dist)
        return 0;
    int pos = c->n < c->max ? c->n++ : c->max - 1;
    while (pos > 0 && c->d[pos - 1] > dist) {
        memcpy(c->q[pos], c->q[pos - 1], sizeof q);
        memcpy(c->nn[pos], c->nn[pos - 1], sizeof q);
        c->d[pos] = c->d[pos - 1];
        pos--;
    }
    memcpy(c->q[pos], q, sizeof q);
    memcpy(c->nn[pos], n, sizeof q);
    c->d[pos] = dist;
    return 0;
}

int pk_mesh_boundary_planes(const pk_mesh_locator *L, const double x[3], double reach, int max,
                            double (*q)[3], double (*n)[3], double *d)
{
    if (max <= 0)
        return 0;
    for (int i = 0; i < max; i++)
        d[i] = INFINITY;
    near_ctx c = {L, x, reach, max, 0, q, n, d};
    pk_grid_query(&L->fg, &L->fb, x, reach, 0, visit_face, &c);
    return c.n;
}

double pk_mesh_boundary_distance(const pk_mesh_locator *L, const double x[3], double reach,
                                 double q[3], double n[3])
{
    double qq[1][3], nn[1][3], d[1];
    /* one plane slot: the nearest face wins (coplanar merging keeps the nearer) */
    int k = pk_mesh_boundary_planes(L, x, reach, 1, qq, nn, d);
    if (k == 0)
        return INFINITY;
    if (q)
        memcpy(q, qq[0], sizeof qq[0]);
    if (n)
        memcpy(n, nn[0], sizeof nn[0]);
    return d[0];
}
