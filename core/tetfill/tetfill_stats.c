/* tetfill_stats.c — characterisation of a filled mesh (Jerier §3.1:
 * coordination Eq. 15, fabric Eq. 17).  Contract: core/tetfill/tetfill_stats.h. */
#include "tetfill_stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/space/grid.h"
#include "core/mesh/mesh_locate.h"

void pk_sym3_eigenvalues(const double a[9], double ev[3])
{
    /* trigonometric solution of the characteristic cubic (Smith 1961) */
    double p1 = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
    double q = (a[0] + a[4] + a[8]) / 3;
    if (p1 == 0) {
        ev[0] = a[0];
        ev[1] = a[4];
        ev[2] = a[8];
    } else {
        double p2 =
            (a[0] - q) * (a[0] - q) + (a[4] - q) * (a[4] - q) + (a[8] - q) * (a[8] - q) + 2 * p1;
        double p = sqrt(p2 / 6), b[9];
        for (int i = 0; i < 9; i++)
            b[i] = (a[i] - (i % 4 == 0 ? q : 0)) / p;
        double r = (b[0] * (b[4] * b[8] - b[5] * b[7]) - b[1] * (b[3] * b[8] - b[5] * b[6]) +
                    b[2] * (b[3] * b[7] - b[4] * b[6])) /
            2;
        double phi = r <= -1 ? M_PI / 3 : r >= 1 ? 0 : acos(r) / 3;
        ev[2] = q + 2 * p * cos(phi);
        ev[0] = q + 2 * p * cos(phi + 2 * M_PI / 3);
        ev[1] = 3 * q - ev[0] - ev[2];
    }
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 - i; j++)
            if (ev[j] > ev[j + 1]) {
                double s = ev[j];
                ev[j] = ev[j + 1];
                ev[j + 1] = s;
            }
}

int pk_tetfill_contact_kind(double gap, double r_min, double eps)
{
    return (gap <= fmax(eps, 1e-9) * r_min ? PK_CONTACT_TOL : 0) |
        (gap <= PK_TETFILL_TANGENT_TOL * r_min ? PK_CONTACT_TANGENT : 0) |
        (gap <= 0 ? PK_CONTACT_TOUCHING : 0);
}

typedef struct coord_ctx {
    const pk_particles *p;
    size_t i, first;
    double r_min, eps;
    pk_tetfill_coord *o;
} coord_ctx;

static int visit_coord(size_t j, const double dx[PK_MAXDIM], double d2, void *vctx)
{
    (void)dx;
    coord_ctx *c = vctx;
    if (j <= c->i || j < c->first || d2 <= 0)
        return 0; /* each pair once */
    int k = pk_tetfill_contact_kind(sqrt(d2) - c->p->r[c->i] - c->p->r[j], c->r_min, c->eps);
    c->o->contacts += (k & PK_CONTACT_TOL) != 0;
    c->o->tangent += (k & PK_CONTACT_TANGENT) != 0;
    c->o->touching += (k & PK_CONTACT_TOUCHING) != 0;
    return 0;
}

void pk_tetfill_coordination(const pk_grid *g, const pk_particles *p, size_t first, double r_min,
                             double eps, pk_tetfill_coord *out)
{
    memset(out, 0, sizeof *out);
    out->n = p->n - first;
    coord_ctx c = {p, 0, first, r_min, eps, out};
    double tau = fmax(eps, 1e-9) * r_min;
    for (size_t i = first; i < p->n; i++) {
        c.i = i;
        pk_grid_query(g, p, &p->x[3 * i], p->r[i], tau, visit_coord, &c);
    }
    double n = out->n ? (double)out->n : 1;
    out->z = 2.0 * (double)out->contacts / n;
    out->z_tangent = 2.0 * (double)out->tangent / n;
    out->z_touching = 2.0 * (double)out->touching / n;
}

typedef struct pair_ctx {
    const pk_particles *p;
    size_t i;
    double r_min, eps, bound, tau;
    pk_tetfill_measures *o;
    int32_t *z;
    double osum;
} pair_ctx;

static int visit_pair(size_t j, const double dx[PK_MAXDIM], double d2, void *vctx)
{
    pair_ctx *c = vctx;
    if (j <= c->i)
        return 0; /* each pair once */
    double d = sqrt(d2), g = d - c->p->r[c->i] - c->p->r[j];
    pk_tetfill_measures *o = c->o;
    if (g < 0) {
        o->pairs_overlapping++;
        o->overlap_max = fmax(o->overlap_max, -g / c->r_min);
        c->osum += -g / c->r_min;
        if (-g > c->bound)
            o->pairs_over_bound++;
    }
    int kind = d > 0 ? pk_tetfill_contact_kind(g, c->r_min, c->eps) : 0;
    o->contacts_touching += (kind & PK_CONTACT_TOUCHING) != 0;
    o->contacts_tangent += (kind & PK_CONTACT_TANGENT) != 0;
    if (kind & PK_CONTACT_TOL) {
        o->contacts++;
        c->z[c->i]++;
        c->z[j]++;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                o->fabric[3 * a + b] += dx[a] * dx[b] / d2;
    }
    return 0;
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return x < y ? -1 : x > y;
}

int pk_tetfill_measure(const pk_mesh *m, const pk_particles *p, double r_min, double eps,
                       pk_tetfill_measures *o)
{
    memset(o, 0, sizeof *o);
    o->n = p->n;
    o->min_wall_clearance = INFINITY;
    pk_mesh_locator L;
    pk_grid g;
    int32_t *z = calloc(p->n ? p->n : 1, sizeof *z);
    int32_t *per_tet = calloc(m->ntet, sizeof *per_tet);
    int32_t *ids = malloc(m->ntet * sizeof *ids);
    if (!z || !per_tet || !ids || pk_mesh_locator_init(&L, m) != 0) {
        free(z);
        free(per_tet);
        free(ids);
        return -1;
    }
    double rmax = r_min, solid = 0;
    for (size_t i = 0; i < p->n; i++)
        rmax = fmax(rmax, p->r[i]);
    int rc = pk_grid_init(&g, &L.box, r_min, rmax, 0, p->n ? p->n : 1);
    for (size_t i = 0; i < p->n && rc == 0; i++)
        rc = pk_grid_insert(&g, p, i);
    /* regions: sorted distinct ids */
    memcpy(ids, m->region, m->ntet * sizeof *ids);
    qsort(ids, m->ntet, sizeof *ids, cmp_i32);
    size_t nr = 0;
    for (size_t e = 0; e < m->ntet; e++)
        if (nr == 0 || ids[e] != ids[nr - 1])
            ids[nr++] = ids[e];
    o->nregion = nr;
    o->region_id = malloc(nr * sizeof *o->region_id);
    o->region_phi = calloc(nr, sizeof *o->region_phi);
    double *rvol = calloc(nr, sizeof *rvol);
    if (!o->region_id || !o->region_phi || !rvol)
        rc = -1;
    for (size_t k = 0; k < nr && rc == 0; k++)
        o->region_id[k] = ids[k];
    pair_ctx c = {p, 0, r_min, eps, eps * r_min * (1 + 1e-9), fmax(eps, 1e-9) * r_min, o, z, 0};
    for (size_t i = 0; i < p->n && rc == 0; i++) {
        c.i = i;
        pk_grid_query(&g, p, &p->x[3 * i], p->r[i], c.tau, visit_pair, &c);
        double Vi = pk_ball_measure(3, p->r[i]);
        solid += Vi;
        long e = pk_mesh_locate(&L, &p->x[3 * i]);
        if (e < 0) {
            o->outside++;
        } else {
            per_tet[e]++;
            int32_t *f = bsearch(&m->region[e], ids, nr, sizeof *ids, cmp_i32);
            o->region_phi[f - ids] += Vi;
        }
        double db = pk_mesh_boundary_distance(&L, &p->x[3 * i], p->r[i] + r_min, NULL, NULL);
        if (isfinite(db))
            o->min_wall_clearance = fmin(o->min_wall_clearance, (db - p->r[i]) / r_min);
    }
    if (rc == 0) {
        for (size_t e = 0; e < m->ntet; e++) {
            int32_t *f = bsearch(&m->region[e], ids, nr, sizeof *ids, cmp_i32);
            rvol[f - ids] += pk_mesh_tet_volume(m, e);
            o->t_hist[per_tet[e] < PK_TETFILL_THIST ? per_tet[e] : PK_TETFILL_THIST - 1]++;
        }
        for (size_t k = 0; k < nr; k++)
            o->region_phi[k] = rvol[k] > 0 ? o->region_phi[k] / rvol[k] : 0;
        for (size_t i = 0; i < p->n; i++)
            o->z_hist[z[i] < PK_TETFILL_ZHIST ? z[i] : PK_TETFILL_ZHIST - 1]++;
        o->overlap_mean = o->pairs_overlapping ? c.osum / (double)o->pairs_overlapping : 0;
        o->z_mean = p->n ? 2.0 * (double)o->contacts / (double)p->n : 0;
        o->z_touching = p->n ? 2.0 * (double)o->contacts_touching / (double)p->n : 0;
        o->z_tangent = p->n ? 2.0 * (double)o->contacts_tangent / (double)p->n : 0;
        for (int k = 0; k < 9; k++)
            o->fabric[k] = o->contacts ? o->fabric[k] / (double)o->contacts : 0;
        pk_sym3_eigenvalues(o->fabric, o->fabric_eig);
        o->phi = solid / m->volume;
        o->spheres_per_tet_mean = (double)(p->n - o->outside) / (double)m->ntet;
    }
    free(rvol);
    free(z);
    free(per_tet);
    free(ids);
    pk_grid_free(&g);
    pk_mesh_locator_free(&L);
    if (rc != 0)
        pk_tetfill_measures_free(o);
    return rc;
}

void pk_tetfill_measures_free(pk_tetfill_measures *o)
{
    free(o->region_id);
    free(o->region_phi);
    o->region_id = NULL;
    o->region_phi = NULL;
    o->nregion = 0;
}
