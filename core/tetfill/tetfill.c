/* tetfill.c — Jerier et al. (2010) geometric filling of a tet mesh with
 * spheres, steps 2–7b.  Contract: core/tetfill/tetfill.h. */
#include "tetfill.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/space/grid.h"
#include "core/mesh/mesh_edges.h"
#include "core/mesh/mesh_locate.h"
#include "core/base/rng.h"
#include "tetfill_tangent.h"

#define MAX_NB 16    /* neighbours list capacity (spheres + planes) */
#define MAX_PLANES 3 /* boundary planes offered as virtual spheres per locus */
#ifndef TETFILL_RETIRE
#define TETFILL_RETIRE 16 /* failed visits in a row that retire a tet from step 7b */
#endif

void pk_tetfill_defaults(pk_tetfill_params *prm)
{
    *prm = (pk_tetfill_params){.eps = 1e-4,
                               .z_min = 3,
                               .contact_rule = PK_TETFILL_CONTACT_TANGENT,
                               .vertex_weight = 0.5,
                               .densify = 1,
                               .neighbours = 8,
                               .max_combos = 30,
                               .max_passes = 1000};
}

typedef struct nb_sphere {
    double s; /* surface distance to the locus */
    double c[3], r;
    int virt; /* 1 = virtual sphere standing for a boundary plane */
} nb_sphere;

typedef struct filler {
    const pk_mesh *m;
    const pk_tetfill_params *prm;
    pk_mesh_locator L;
    pk_particles *p;
    size_t first; /* p's grains before this run (not ours) */
    pk_grid g;
    pk_rng rng;
    double tau;  /* contact tolerance (query reach) */
    double zgap; /* a gap <= zgap is a contact in the z_min test */
    double Rv;   /* virtual sphere radius */
    double V, solid;
    pk_monitor *mon;
    pk_progress prog;
    pk_tetfill_stats *st;
    int stop; /* 0 go, 1 target reached, 2 cancelled/time/limit */
    int open; /* steps 4–6 before 7a (trim_after_loci): no boundary, bounding box only */
    /* scratch for the acceptance query */
    double *nd, *nr;
    size_t nn, ncap;
    /* scratch for the nearest list */
    nb_sphere nb[MAX_NB];
    int nnb, k;
} filler;

static int rebuild_grid(filler *F, size_t cap)
{
    pk_grid_free(&F->g);
    pk_box b = F->L.box;
    if (pk_grid_init(&F->g, &b, F->prm->r_min, F->prm->r_max, 0, cap) != 0)
        return -1;
    for (size_t i = F->first; i < F->p->n; i++)
        if (pk_grid_insert(&F->g, F->p, i) != 0)
            return -1;
    return 0;
}

static int tick(filler *F, int force)
{
    if (!F->mon)
        return 0;
    F->prog.done = F->p->n - F->first;
    F->prog.phi = F->solid / F->V;
    F->prog.fraction = F->prm->phi_target > 0 ? fmin(1, F->prog.phi / F->prm->phi_target)
        : F->prm->n_target ? fmin(1, (double)F->prog.done / (double)F->prm->n_target)
                           : -1;
    int rc = pk_monitor_tick(F->mon, &F->prog, force);
    if (rc) {
        F->stop = 2;
        F->st->reason = rc == 1 ? PK_STOP_CANCELLED : PK_STOP_WALL_TIME;
    }
    return rc;
}

static void check_targets(filler *F)
{
    const pk_tetfill_params *prm = F->prm;
    size_t n = F->p->n - F->first;
    if ((prm->phi_target > 0 && F->solid >= prm->phi_target * F->V) ||
        (prm->n_target && n >= prm->n_target)) {
        F->stop = 1;
        F->st->reason = PK_STOP_COMPLETE;
    } else if (prm->max_spheres && n >= prm->max_spheres) {
        F->stop = 2;
        F->st->reason = PK_STOP_NO_ROOM;
    }
}

/* Append a sphere (grid kept in step). */
static int add_sphere(filler *F, const double x[3], double r)
{
    if (F->p->n + 1 > F->g.cap && rebuild_grid(F, 2 * F->g.cap + 1024) != 0)
        return -1;
    size_t i = pk_particles_push(F->p, x, r, 0);
    if (i == (size_t)-1 || pk_grid_insert(&F->g, F->p, i) != 0)
        return -1;
    F->solid += pk_ball_measure(3, r);
    check_targets(F);
    if ((F->p->n & 255) == 0)
        tick(F, 0);
    return 0;
}

/* Radius of a direct sphere (steps 2–3): over r_max → uniform in the range,
 * under r_min → r_min (Jerier §2.2). */
static double clamp_radius(filler *F, double r)
{
    if (r > F->prm->r_max)
        return pk_rng_range(&F->rng, F->prm->r_min, F->prm->r_max);
    return r < F->prm->r_min ? F->prm->r_min : r;
}

/* Steps 2–3. */
static int direct_spheres(filler *F)
{
    const pk_mesh *m = F->m;
    pk_mesh_edge_list el;
    if (pk_mesh_edges(m, &el) != 0)
        return -1;
    double *ls = malloc(m->nnode * sizeof *ls); /* shortest adjacent edge */
    if (!ls) {
        pk_mesh_edges_free(&el);
        return -1;
    }
    for (size_t i = 0; i < m->nnode; i++)
        ls[i] = INFINITY;
    int rc = 0;
    for (size_t i = 0; i < el.n && rc == 0; i++) {
        double l = pk_mesh_edge_length(m, &el, i);
        const double *a = &m->x[3 * (size_t)el.v[2 * i]], *b = &m->x[3 * (size_t)el.v[2 * i + 1]];
        double c[3] = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
        rc = add_sphere(F, c, clamp_radius(F, l / 8));
        for (int k = 0; k < 2; k++)
            ls[el.v[2 * i + k]] = fmin(ls[el.v[2 * i + k]], l);
    }
    for (size_t i = 0; i < m->nnode && rc == 0; i++)
        if (isfinite(ls[i]))
            rc = add_sphere(F, &m->x[3 * i], clamp_radius(F, ls[i]));
    free(ls);
    pk_mesh_edges_free(&el);
    return rc;
}

typedef struct shrink_ctx {
    filler *F;
    size_t i;
} shrink_ctx;

/* Jerier §2.2: r_i, r_j ← k r_i, k r_j with k = 1 + g/(r_i + r_j)
 * brings the pair to contact; radii only decrease, so one sweep suffices. */
static int visit_shrink(size_t j, const double dx[PK_MAXDIM], double d2, void *vctx)
{
    (void)dx;
    shrink_ctx *c = vctx;
    pk_particles *p = c->F->p;
    if (j == c->i)
        return 0;
    double ri = p->r[c->i], rj = p->r[j], g = sqrt(d2) - ri - rj;
    if (g < -c->F->prm->eps * c->F->prm->r_min) {
        double k = fmax(0, 1 + g / (ri + rj));
        p->r[c->i] = k * ri;
        p->r[j] = k * rj;
    }
    return 0;
}

/* Keep the grains for which keep() is true; rebuild the grid and φ. */
static int compact(filler *F, int (*keep)(filler *, size_t))
{
    pk_particles *p = F->p;
    size_t w = F->first;
    F->solid = 0;
    for (size_t i = F->first; i < p->n; i++) {
        if (!keep(F, i))
            continue;
        memcpy(&p->x[3 * w], &p->x[3 * i], 3 * sizeof *p->x);
        p->r[w] = p->r[i];
        p->species[w] = p->species[i];
        F->solid += pk_ball_measure(3, p->r[w]);
        w++;
    }
    p->n = w;
    return rebuild_grid(F, F->g.cap);
}

static int keep_large(filler *F, size_t i) { return F->p->r[i] >= F->prm->r_min * (1 - 1e-12); }

/* Step 7a: the centre in the mesh and no boundary overlap beyond ε r_min. */
static int keep_inside(filler *F, size_t i)
{
    const double *x = &F->p->x[3 * i];
    double r = F->p->r[i];
    if (pk_mesh_locate(&F->L, x) < 0)
        return 0;
    double db = pk_mesh_boundary_distance(&F->L, x, r, NULL, NULL);
    return db >= r - F->prm->eps * F->prm->r_min;
}

/* Step 7a: n_trimmed counts what it removes. */
static int trim(filler *F)
{
    size_t n = F->p->n;
    int rc = compact(F, keep_inside);
    F->st->n_trimmed = n - F->p->n;
    return rc;
}

static int reduce_overlaps(filler *F)
{
    shrink_ctx c = {F, 0};
    for (size_t i = F->first; i < F->p->n; i++) {
        c.i = i;
        pk_grid_query(&F->g, F->p, &F->p->x[3 * i], F->p->r[i], 0, visit_shrink, &c);
    }
    return compact(F, keep_large);
}

static int visit_collect(size_t j, const double dx[PK_MAXDIM], double d2, void *vctx)
{
    (void)dx;
    filler *F = vctx;
    if (F->nn == F->ncap) {
        size_t cap = F->ncap ? 2 * F->ncap : 64;
        double *a = realloc(F->nd, cap * sizeof *a), *b;
        if (!a)
            return 1;
        F->nd = a;
        b = realloc(F->nr, cap * sizeof *b);
        if (!b)
            return 1;
        F->nr = b;
        F->ncap = cap;
    }
    F->nd[F->nn] = sqrt(d2);
    F->nr[F->nn++] = F->p->r[j];
    return 0;
}

/* Acceptance tests of a candidate (x, r) (Jerier §2.2).
 * 1 = added, 0 = rejected, -1 = out of memory. */
static int try_candidate(filler *F, const double x[3], double r)
{
    const pk_tetfill_params *prm = F->prm;
    double dmax = prm->eps * prm->r_min;
    if (r < prm->r_min || r > prm->r_max)
        return 0;
    /* cheap test first: the locus's nearest spheres and planes (most rejections) */
    for (int i = 0; i < F->nnb; i++) {
        const nb_sphere *s = &F->nb[i];
        double d2 = 0;
        for (int k = 0; k < 3; k++)
            d2 += (x[k] - s->c[k]) * (x[k] - s->c[k]);
        if (sqrt(d2) - s->r + dmax < prm->r_min)
            return 0;
    }
    if (x[0] < 0 || x[1] < 0 || x[2] < 0 || x[0] > F->L.box.L[0] || x[1] > F->L.box.L[1] ||
        x[2] > F->L.box.L[2])
        return 0;
    double rn = r;
    F->nn = 0;
    if (pk_grid_query(&F->g, F->p, x, r, F->tau, visit_collect, F) != 0)
        return -1;
    for (size_t i = 0; i < F->nn; i++)
        rn = fmin(rn, F->nd[i] - F->nr[i] + dmax);
    if (rn < prm->r_min || (!F->open && pk_mesh_locate(&F->L, x) < 0))
        return 0;
    /* the boundary faces as virtual spheres, unless 7a comes later */
    double db = F->open ? INFINITY : pk_mesh_boundary_distance(&F->L, x, r + F->tau, NULL, NULL);
    if (db + dmax < rn)
        rn = db + dmax;
    if (rn < prm->r_min)
        return 0;
    int z = db - rn <= F->zgap;
    for (size_t i = 0; i < F->nn; i++)
        z += F->nd[i] - rn - F->nr[i] <= F->zgap;
    if (z < prm->z_min)
        return 0;
    return add_sphere(F, x, rn) == 0 ? 1 : -1;
}

/* Keep the k nearest by surface distance (insertion into a short sorted list). */
static void nb_insert(filler *F, const nb_sphere *s)
{
    if (F->nnb == F->k && F->nb[F->k - 1].s <= s->s)
        return;
    int pos = F->nnb < F->k ? F->nnb++ : F->k - 1;
    while (pos > 0 && F->nb[pos - 1].s > s->s) {
        F->nb[pos] = F->nb[pos - 1];
        pos--;
    }
    F->nb[pos] = *s;
}

static int visit_nearest(size_t j, const double dx[PK_MAXDIM], double d2, void *vctx)
{
    (void)dx;
    filler *F = vctx;
    nb_sphere s = {.s = sqrt(d2) - F->p->r[j], .r = F->p->r[j], .virt = 0};
    memcpy(s.c, &F->p->x[3 * j], sizeof s.c);
    nb_insert(F, &s);
    return 0;
}

/* Last resort for a hole larger than r_max: a sphere of radius r_max tangent
 * to three of the four (trilateration), centre nearest the locus first. */
static int try_three(filler *F, const double q[3], const nb_sphere *const s[4])
{
    for (int omit = 3; omit >= 0; omit--) {
        double c[3][3], r[3], x[2][3];
        for (int i = 0, k = 0; i < 4; i++)
            if (i != omit) {
                memcpy(c[k], s[i]->c, sizeof c[k]);
                r[k++] = s[i]->r;
            }
        int n = pk_tangent_sphere3(c, r, F->prm->r_max, x);
        double d0 = 0, d1 = 0;
        for (int k = 0; k < 3 && n == 2; k++) {
            d0 += (x[0][k] - q[k]) * (x[0][k] - q[k]);
            d1 += (x[1][k] - q[k]) * (x[1][k] - q[k]);
        }
        for (int i = 0; i < n; i++) {
            int rc = try_candidate(F, x[(d1 < d0) ^ i], F->prm->r_max);
            if (rc != 0)
                return rc;
        }
    }
    return 0;
}

/* The geometric procedure at locus q (Jerier §2.1).  1 added, 0 not, -1 error.
 * void_only: give up at once if q lies inside a sphere (densification draws
 * another locus instead: at φ ≈ 0.6 most random points do). */
static int try_locus(filler *F, const double q[3], int void_only)
{
    const pk_tetfill_params *prm = F->prm;
    F->st->loci++;
    F->k = prm->neighbours;
    F->nnb = 0;
    /* q inside a sphere: the cheap first-hit test of the grid */
    if (void_only && pk_grid_overlaps(&F->g, F->p, q, 0))
        return 2;
    /* The k nearest by surface distance within 2 r_max (at least 4, reach
     * doubled up to 3 times).  A query of reach ρ reports every sphere with
     * surface distance < ρ, so once it holds k of them they are the k nearest:
     * start small and double — a 2 r_max query scans ~(4 r_max / h)³ cells of
     * each fine level, the cost of the whole filler at large R. */
    double full = 2 * prm->r_max, reach = fmin(prm->r_min, full);
    for (int attempt = 0; attempt < 64; attempt++) {
        F->nnb = 0;
        pk_grid_query(&F->g, F->p, q, 0, reach, visit_nearest, F);
        if (F->nnb >= F->k || (reach >= full && F->nnb >= 4) || reach >= 8 * full)
            break;
        reach = reach < full ? fmin(2 * reach, full) : 2 * reach;
    }
    double pq[MAX_PLANES][3], pn[MAX_PLANES][3], pd[MAX_PLANES];
    int np =
        F->open ? 0 : pk_mesh_boundary_planes(&F->L, q, fmax(reach, full), MAX_PLANES, pq, pn, pd);
    for (int i = 0; i < np; i++) {
        nb_sphere s = {.s = pd[i], .r = F->Rv, .virt = 1};
        for (int k = 0; k < 3; k++)
            s.c[k] = pq[i][k] + F->Rv * pn[i][k];
        nb_insert(F, &s);
    }
    int n = F->nnb, tried = 0;
    if (n < 4)
        return 0;
    for (int a = 0; a < n - 3; a++)
        for (int b = a + 1; b < n - 2; b++)
            for (int c = b + 1; c < n - 1; c++)
                for (int d = c + 1; d < n; d++) {
                    if (tried++ >= prm->max_combos)
                        return 0;
                    const nb_sphere *s[4] = {&F->nb[a], &F->nb[b], &F->nb[c], &F->nb[d]};
                    if (s[0]->virt + s[1]->virt + s[2]->virt + s[3]->virt == 4)
                        continue;
                    double cc[4][3], rr[4], x[2][3], r[2];
                    for (int i = 0; i < 4; i++) {
                        memcpy(cc[i], s[i]->c, sizeof cc[i]);
                        rr[i] = s[i]->r;
                    }
                    int nroot;
                    F->st->solves++;
                    if (pk_tangent_sphere(cc, rr, PK_TETFILL_TANGENT_TOL * prm->r_min, x, r,
                                          &nroot) == PK_TANGENT_SINGULAR) {
                        F->st->singular++;
                        continue;
                    }
                    /* root choice: inside the quadruple's tet first,
                     * then the smaller */
                    int order[2] = {0, 1};
                    if (nroot == 2 && !pk_point_in_tet(cc, x[0]) && pk_point_in_tet(cc, x[1])) {
                        order[0] = 1;
                        order[1] = 0;
                    }
                    int too_big = 0;
                    for (int i = 0; i < nroot; i++) {
                        too_big |= r[order[i]] > prm->r_max;
                        int rc = try_candidate(F, x[order[i]], r[order[i]]);
                        if (rc != 0) {
                            if (rc > 0)
                                F->st->accepted++;
                            return rc;
                        }
                    }
                    /* not in 7b: there it never succeeds (every three-sphere
                     * sphere of the cube sweeps comes from steps 4–6) and cost
                     * 40 % of the run */
                    if (too_big && prm->z_min <= 3 && !void_only) {
                        int rc = try_three(F, q, s);
                        if (rc != 0) {
                            if (rc > 0)
                                F->st->accepted_three++;
                            return rc;
                        }
                    }
                }
    return 0;
}

/* Fisher–Yates shuffle of a[0..n). */
static void shuffle(filler *F, size_t *a, size_t n)
{
    for (size_t i = n; i > 1; i--) {
        size_t j = (size_t)(pk_rng_uniform(&F->rng) * (double)i);
        if (j >= i)
            j = i - 1;
        size_t s = a[i - 1];
        a[i - 1] = a[j];
        a[j] = s;
    }
}

static size_t *shuffled(filler *F, size_t n)
{
    size_t *o = malloc((n ? n : 1) * sizeof *o);
    if (!o)
        return NULL;
    for (size_t i = 0; i < n; i++)
        o[i] = i;
    shuffle(F, o, n);
    return o;
}

static void centroid(const pk_mesh *m, const int32_t *v, int nv, double c[3])
{
    c[0] = c[1] = c[2] = 0;
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++)
            c[k] += m->x[3 * (size_t)v[i] + k] / nv;
}

/* Steps 4–6. */
static int geometric_loci(filler *F)
{
    const pk_mesh *m = F->m;
    int32_t *faces;
    size_t nf;
    if (pk_mesh_faces(m, &faces, &nf) != 0)
        return -1;
    size_t *o = shuffled(F, nf);
    int rc = o ? 0 : -1;
    for (size_t i = 0; i < nf && rc >= 0 && !F->stop; i++) {
        double c[3];
        centroid(m, &faces[3 * o[i]], 3, c);
        rc = try_locus(F, c, 0);
        if ((i & 255) == 0)
            tick(F, 0);
    }
    free(o);
    free(faces);
    if (rc < 0 || F->prm->skip_tet_loci)
        return rc < 0 ? -1 : 0;
    o = shuffled(F, m->ntet);
    if (!o)
        return -1;
    for (size_t i = 0; i < m->ntet && rc >= 0 && !F->stop; i++) { /* step 5 */
        double c[3];
        centroid(m, &m->t[4 * o[i]], 4, c);
        rc = try_locus(F, c, 0);
        if ((i & 255) == 0)
            tick(F, 0);
    }
    double w = F->prm->vertex_weight;
    for (size_t i = 0; i < m->ntet && rc >= 0 && !F->stop; i++) { /* step 6 */
        const int32_t *t = &m->t[4 * o[i]];
        double c[3];
        centroid(m, t, 4, c);
        for (int k = 0; k < 4 && rc >= 0 && !F->stop; k++) {
            double q[3];
            for (int j = 0; j < 3; j++)
                q[j] = c[j] + w * (m->x[3 * (size_t)t[k] + j] - c[j]);
            rc = try_locus(F, q, 0);
        }
        if ((i & 63) == 0)
            tick(F, 0);
    }
    free(o);
    return rc < 0 ? -1 : 0;
}

/* One locus in tet t's empty space: up to 8 uniform draws until one is in no
 * sphere, then the geometric procedure.  1 added, 0/2 not, -1 error. */
static int void_locus(filler *F, const int32_t *t)
{
    const pk_mesh *m = F->m;
    int rc = 2;
    for (int draw = 0; draw < 8 && rc == 2; draw++) {
        double u[3] = {pk_rng_uniform(&F->rng), pk_rng_uniform(&F->rng), pk_rng_uniform(&F->rng)};
        for (int a = 0; a < 2; a++) /* sorted: uniform barycentric coordinates */
            for (int b = 0; b < 2 - a; b++)
                if (u[b] > u[b + 1]) {
                    double s = u[b];
                    u[b] = u[b + 1];
                    u[b + 1] = s;
                }
        double l[4] = {u[0], u[1] - u[0], u[2] - u[1], 1 - u[2]}, q[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
            for (int j = 0; j < 3; j++)
                q[j] += l[k] * m->x[3 * (size_t)t[k] + j];
        rc = try_locus(F, q, 1);
    }
    return rc;
}

/* Step 7b: passes over the active tets, one random void locus per tet per
 * pass.  A tet retires after TETFILL_RETIRE visits in a row that add nothing,
 * so the total work is at most (spheres added + TETFILL_RETIRE·tets) visits —
 * linear — and the passes end by themselves when every tet is retired (the
 * paper's "until no more sphere can be added"), or after two passes that add
 * nothing (Jerier's code), max_passes, or the stop target. */
static int densify(filler *F)
{
    const pk_mesh *m = F->m;
    size_t *act = shuffled(F, m->ntet), nact = m->ntet;
    uint8_t *fails = calloc(m->ntet ? m->ntet : 1, 1);
    int idle = 0, rc = 0;
    if (!act || !fails) {
        free(act);
        free(fails);
        return -1;
    }
    for (int pass = 0; pass < F->prm->max_passes && idle < 2 && nact && !F->stop && rc >= 0;
         pass++) {
        size_t before = F->p->n, w = 0, i = 0;
        if (pass)
            shuffle(F, act, nact);
        for (; i < nact && rc >= 0 && !F->stop; i++) {
            size_t t = act[i];
            rc = void_locus(F, &m->t[4 * t]);
            fails[t] = rc == 1 ? 0 : (uint8_t)(fails[t] + 1);
            if (fails[t] < TETFILL_RETIRE)
                act[w++] = t;
            if ((i & 255) == 0)
                tick(F, 0);
        }
        while (i < nact) /* stopped mid-pass: keep the rest */
            act[w++] = act[i++];
        nact = w;
        F->st->passes = pass + 1;
        idle = F->p->n == before ? idle + 1 : 0;
    }
    free(act);
    free(fails);
    return rc < 0 ? -1 : 0;
}

int pk_tetfill(const pk_mesh *m, const pk_tetfill_params *prm, pk_monitor *mon, pk_particles *p,
               pk_tetfill_stats *st)
{
    memset(st, 0, sizeof *st);
    st->reason = PK_STOP_ERROR;
    if (!(prm->r_min > 0) || !(prm->r_max >= prm->r_min) || !(prm->eps >= 0) ||
        (prm->contact_rule != PK_TETFILL_CONTACT_TANGENT &&
         prm->contact_rule != PK_TETFILL_CONTACT_TOUCHING) ||
        prm->neighbours < 4 || prm->neighbours > MAX_NB - MAX_PLANES || prm->max_combos < 1 ||
        !(m->volume > 0) || p->dim != 3)
        return -1;
    double t0 = pk_wall_seconds();
    filler F = {.m = m, .prm = prm, .p = p, .first = p->n, .mon = mon, .st = st, .V = m->volume};
    F.tau = fmax(prm->eps * prm->r_min, 1e-9 * prm->r_min);
    /* touching (YADE SpherePadder place_fifth_sphere: distance <= 0) */
    F.zgap = prm->contact_rule == PK_TETFILL_CONTACT_TOUCHING ? 0 : F.tau;
    F.Rv = 100 * m->edge_mean;
    F.prog.stage = "tetfill";
    F.prog.eta_s = -1;
    pk_rng_seed(&F.rng, prm->seed, 0);
    int rc = -1;
    if (pk_mesh_locator_init(&F.L, m) != 0)
        goto out;
    /* capacity guess: direct spheres plus what the volume holds at r_min */
    size_t cap = 8 * m->ntet + m->nnode + 1024;
    if (rebuild_grid(&F, cap) != 0)
        goto out;
    if (mon)
        pk_monitor_begin(mon);
    st->reason = PK_STOP_COMPLETE;
    if (direct_spheres(&F) != 0 || reduce_overlaps(&F) != 0)
        goto out;
    st->n_direct = p->n - F.first;
    if (F.stop == 1)
        F.stop = 0; /* direct spheres do not count against a target */
    F.open = prm->trim_after_loci;
    if (!F.open && trim(&F) != 0)
        goto out;
    check_targets(&F);
    if (!F.stop && geometric_loci(&F) != 0)
        goto out;
    st->n_geometric = p->n - F.first;
    st->phi_geometric = F.solid / F.V;
    pk_tetfill_coordination(&F.g, p, F.first, prm->r_min, prm->eps, &st->geometric);
    st->seconds_geometric = pk_wall_seconds() - t0;
    if (F.open) { /* the paper's order: 7a after the state of steps 1–6 */
        F.open = 0;
        if (trim(&F) != 0)
            goto out;
        if (F.stop == 1)
            F.stop = 0; /* the target counts inside the mesh */
        check_targets(&F);
    }
    if (!F.stop && prm->densify && densify(&F) != 0)
        goto out;
    if (!F.stop && (prm->phi_target > 0 || prm->n_target))
        st->reason = PK_STOP_STALLED; /* saturated below the target */
    rc = 0;
out:
    if (rc != 0)
        st->reason = PK_STOP_ERROR;
    st->n_final = p->n - F.first;
    st->phi = F.solid / F.V;
    st->seconds = pk_wall_seconds() - t0;
    if (mon && rc == 0)
        tick(&F, 1);
    pk_grid_free(&F.g);
    pk_mesh_locator_free(&F.L);
    free(F.nd);
    free(F.nr);
    return rc;
}
