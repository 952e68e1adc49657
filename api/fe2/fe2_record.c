/* fe2_record.c — the fe2 run's record and its H5MD-style layout; the
 * contract is in fe2_record.h. */
#include "fe2_record.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int push(pk_fe2_dbuf *d, const double *v, size_t n)
{
    if (d->n + n > d->cap) {
        size_t c = d->cap ? 2 * d->cap : 64;
        while (c < d->n + n)
            c *= 2;
        double *p = realloc(d->v, c * sizeof *p);
        if (!p)
            return -1;
        d->v = p;
        d->cap = c;
    }
    if (n)
        memcpy(d->v + d->n, v, n * sizeof *v);
    d->n += n;
    return 0;
}

static int push1(pk_fe2_dbuf *d, double v) { return push(d, &v, 1); }

/* The area of the mesh with nodes at x (Σ of the elements' polygons). */
static double mesh_area(const pk_fe2_mesh *m, const double *x)
{
    double a = 0;
    for (size_t e = 0; e < m->nelem; e++) {
        int nen = pk_fe2_elem_nodes(m, e);
        for (int i = 0; i < nen; i++) {
            size_t p = (size_t)m->conn[4 * e + i], q = (size_t)m->conn[4 * e + (i + 1) % nen];
            a += 0.5 * (x[2 * p] * x[2 * q + 1] - x[2 * q] * x[2 * p + 1]);
        }
    }
    return a;
}

/* The fe2 process's observables (h5_observables.h), per unit thickness:
 * the summary's members, their datasets under /observables/fe2 and their
 * units.  Scalars are written from the run's values (pk_h5_obs_rows), the
 * record's series and arrays here. */
#define S(name, kind)                                                                              \
    {                                                                                              \
        name, kind, PK_OBS_SCALAR, "fe2/" name                                                     \
    }
#define FILE_ONLY(file, kind)                                                                      \
    {                                                                                              \
        "fe2/" file, kind, PK_OBS_FILE, NULL                                                       \
    }
const pk_obs_row pk_fe2_observables[] = {
    S("termination_reason", PK_U_NONE),
    S("steps", PK_U_NONE),
    S("steps_requested", PK_U_NONE),
    S("nodes", PK_U_NONE),
    S("elements", PK_U_NONE),
    S("gauss_points", PK_U_NONE),
    S("rve_particles", PK_U_NONE),
    S("boundary_condition", PK_U_NONE),
    S("E_n", PK_U_STIFFNESS),
    S("newton_iterations_total", PK_U_NONE),
    S("step_cuts_total", PK_U_NONE),
    /* how the run went (docs/perf/fe2-mpi.md), in the summary alone */
    {"threads", PK_U_NONE, PK_OBS_RUN, NULL},
    {"mpi_ranks", PK_U_NONE, PK_OBS_RUN, NULL},
    {"evaluation_rounds", PK_U_NONE, PK_OBS_RUN, NULL},
    {"steps_wall_s", PK_U_SECONDS, PK_OBS_RUN, NULL},
    {"mpi_bytes_sent", PK_U_NONE, PK_OBS_RUN, NULL},
    {"mpi_bytes_received", PK_U_NONE, PK_OBS_RUN, NULL},
    /* per converged step: reactions of the displacement conditions (by
     * name, their component), the dilatancy, the load time */
    {"reaction_per_step", PK_U_FORCE_PER_THICKNESS, PK_OBS_RECORD, "fe2/reaction"},
    {"dilatancy_percent_per_step", PK_U_NONE, PK_OBS_RECORD, "fe2/dilatancy_percent"},
    {"time_per_step", PK_U_NONE, PK_OBS_RECORD, "fe2/load_steps/time"},
    FILE_ONLY("mesh/nodes", PK_U_LENGTH),
    FILE_ONLY("mesh/gauss_position", PK_U_LENGTH),
    FILE_ONLY("mesh/gauss_weight", PK_U_AREA),
    FILE_ONLY("displacement", PK_U_LENGTH),
    FILE_ONLY("position", PK_U_LENGTH),
    FILE_ONLY("piola_stress", PK_U_PLANE_STRESS),
    FILE_ONLY("cauchy_stress", PK_U_PLANE_STRESS),
    FILE_ONLY("von_mises", PK_U_PLANE_STRESS),
    FILE_ONLY("von_mises_element", PK_U_PLANE_STRESS),
    FILE_ONLY("rve/energy_density", PK_U_PLANE_STRESS),
    FILE_ONLY("area", PK_U_AREA),
    FILE_ONLY("reference_area", PK_U_AREA),
    FILE_ONLY("micro", PK_U_LENGTH), /* the RVE centres micro/gauss_point_<g> */
    FILE_ONLY("newton/solves/abs_residual_0", PK_U_FORCE_PER_THICKNESS),
    {NULL, PK_U_NONE, PK_OBS_SCALAR, NULL},
};
#undef S
#undef FILE_ONLY

const char *pk_fe2_unit_of(const char *name, const pk_units *u)
{
    return pk_obs_unit_at(pk_fe2_observables, name, u);
}

int pk_fe2_record_init(pk_fe2_record *r, const pk_fe2_setup *s, const size_t *micro_gp,
                       size_t nmicro, size_t ngrain)
{
    memset(r, 0, sizeof *r);
    r->s = s;
    r->ngp = pk_fe2_gauss_count(&s->mesh);
    r->micro_gp = micro_gp;
    r->nmicro = nmicro;
    r->ngrain = ngrain;
    r->area0 = mesh_area(&s->mesh, s->mesh.xy);
    return 0;
}

void pk_fe2_record_free(pk_fe2_record *r)
{
#define B(m) offsetof(pk_fe2_record, m)
    static const size_t bufs[] = {B(step),
                                  B(time),
                                  B(stage),
                                  B(cuts),
                                  B(u),
                                  B(x),
                                  B(F),
                                  B(P),
                                  B(sigma),
                                  B(mises),
                                  B(mises_elem),
                                  B(energy),
                                  B(coordination),
                                  B(rattlers),
                                  B(relax_iter),
                                  B(reaction),
                                  B(area),
                                  B(dilatancy),
                                  B(micro_x),
                                  B(part_step),
                                  B(part_t0),
                                  B(part_t1),
                                  B(part_n),
                                  B(part_abs0),
                                  B(part_conv),
                                  B(it_part),
                                  B(it_res),
                                  B(it_eta)};
#undef B
    for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
        free(((pk_fe2_dbuf *)((char *)r + bufs[i]))->v);
    memset(r, 0, sizeof *r);
}

int pk_fe2_record_newton(pk_fe2_record *r, size_t step, const pk_fe2_step_report *rep)
{
    int rc = 0;
    for (size_t p = 0; p < rep->nparts; p++) {
        const pk_fe2_iterations *it = &rep->parts[p];
        double part = (double)r->part_step.n;
        rc |= push1(&r->part_step, (double)step) | push1(&r->part_t0, it->t0) |
            push1(&r->part_t1, it->t1) | push1(&r->part_n, it->n) |
            push1(&r->part_abs0, it->abs_res0) | push1(&r->part_conv, it->converged);
        for (int k = 0; k < it->n && k < 64; k++)
            rc |= push1(&r->it_part, part) | push1(&r->it_res, it->res[k]) |
                push1(&r->it_eta, it->ls_eta[k]);
    }
    return rc ? -1 : 0;
}

int pk_fe2_record_step(pk_fe2_record *r, size_t step, double time, size_t stage, int cuts,
                       const pk_fe2_state *st, const double *const *micro_pos)
{
    const pk_fe2_setup *s = r->s;
    const pk_fe2_mesh *m = &s->mesh;
    int rc = push1(&r->step, (double)step) | push1(&r->time, time) |
        push1(&r->stage, (double)stage) | push1(&r->cuts, cuts);
    rc |= push(&r->u, st->u, s->ndof);
    double *x = malloc(s->ndof * sizeof *x), *el = calloc(m->nelem + 1, sizeof *el),
           *we = calloc(m->nelem + 1, sizeof *we);
    if (!x || !el || !we) {
        free(x), free(el), free(we);
        return -1;
    }
    for (size_t d = 0; d < s->ndof; d++)
        x[d] = m->xy[d] + st->u[d];
    rc |= push(&r->x, x, s->ndof);
    rc |= push(&r->F, st->F, 4 * r->ngp) | push(&r->P, st->P, 4 * r->ngp);
    for (size_t g = 0; g < r->ngp; g++) {
        double sig[4], w;
        size_t e;
        pk_fe2_cauchy(&st->F[4 * g], &st->P[4 * g], sig);
        double vm = pk_fe2_von_mises(sig);
        rc |= push(&r->sigma, sig, 4) | push1(&r->mises, vm);
        pk_fe2_gauss_point(m, g, NULL, &e, &w);
        el[e] += w * vm;
        we[e] += w;
        const pk_fe2_gp_info *gi = &st->gp[g];
        rc |= push1(&r->energy, gi->energy) | push1(&r->coordination, gi->coordination) |
            push1(&r->rattlers, (double)gi->rattlers) |
            push1(&r->relax_iter, (double)gi->relax_iter);
    }
    for (size_t e = 0; e < m->nelem; e++)
        el[e] = we[e] > 0 ? el[e] / we[e] : 0;
    rc |= push(&r->mises_elem, el, m->nelem);
    /* reactions of each displacement condition: Σ (f_int − f_ext) over its nodes */
    for (size_t k = 0; k < s->nbc; k++) {
        double re[2] = {0, 0};
        for (size_t i = 0; s->bc[k].type == PK_FE2_DISPLACEMENT && i < s->bc[k].set->nnode; i++)
            for (int c = 0; c < 2; c++) {
                size_t d = 2 * (size_t)s->bc[k].set->node[i] + (size_t)c;
                re[c] += st->fint[d] - st->fext[d];
            }
        rc |= push(&r->reaction, re, 2);
    }
    double a = mesh_area(m, x);
    rc |= push1(&r->area, a) | push1(&r->dilatancy, (a / r->area0 - 1) * 100);
    for (size_t i = 0; micro_pos && i < r->nmicro; i++)
        for (size_t j = 0; j < r->ngrain; j++)
            rc |= push(&r->micro_x, &micro_pos[i][3 * j], 2);
    free(x), free(el), free(we);
    r->nstep += rc == 0;
    return rc ? -1 : 0;
}

/* ---- writing */

static int arr(pk_h5 *h, const char *path, int rank, const size_t *dims, const double *v,
               const char *unit)
{
    size_t n = 1;
    for (int i = 0; i < rank; i++)
        n *= dims[i];
    return pk_h5_write_array(h, path, PK_H5_F64, rank, dims, n ? v : (const double[]){0}, unit);
}

static int iarr(pk_h5 *h, const char *path, const double *v, size_t n)
{
    int64_t *a = malloc((n + 1) * sizeof *a);
    if (!a)
        return -1;
    for (size_t i = 0; i < n; i++)
        a[i] = (int64_t)v[i];
    int rc = pk_h5_write_array(h, path, PK_H5_I64, 1, &n, a, NULL);
    free(a);
    return rc;
}

/* An H5MD time series /observables/fe2/<name> [nstep]×dims, its unit that
 * of "fe2/<unit_name>" (NULL: name; h5_units.c); step and time are written with the
 * first series (the clock) and linked from it by the others. */
static int series(pk_h5 *h, const pk_fe2_record *r, char *clock, const char *name,
                  const char *unit_name, const pk_fe2_dbuf *d, int rank, const size_t *dims,
                  const pk_units *u)
{
    char p[200], un[200];
    size_t all[3] = {r->nstep, 0, 0};
    for (int i = 0; i < rank && i < 2; i++)
        all[i + 1] = dims[i];
    int64_t *step = malloc((r->nstep + 1) * sizeof *step);
    if (!step)
        return -1;
    for (size_t k = 0; k < r->nstep; k++)
        step[k] = (int64_t)r->step.v[k];
    snprintf(p, sizeof p, "/observables/fe2/%s", name);
    snprintf(un, sizeof un, "fe2/%s", unit_name ? unit_name : name);
    static const double none[1] = {0};
    int rc =
        pk_h5_time_element(h, p, *clock ? clock : NULL, step, r->nstep ? r->time.v : none, NULL,
                           PK_H5_F64, rank + 1, all, d->n ? d->v : none, pk_fe2_unit_of(un, u));
    free(step);
    if (!*clock)
        snprintf(clock, 200, "%s", p);
    return rc;
}

int pk_fe2_record_write(pk_h5 *h, const pk_fe2_record *r, const pk_units *u)
{
    char clock[200] = "";
    const pk_fe2_setup *s = r->s;
    const pk_fe2_mesh *m = &s->mesh;
    int rc = 0;
    /* the mesh and its Gauss points */
    size_t d2[2] = {m->nnode, 2}, d4[2] = {m->nelem, 4};
    rc |= arr(h, "/observables/fe2/mesh/nodes", 2, d2, m->xy, pk_fe2_unit_of("fe2/mesh/nodes", u));
    rc |= pk_h5_write_array(h, "/observables/fe2/mesh/elements", PK_H5_I32, 2, d4, m->conn, NULL);
    /* the XDMF topology: one array per element kind, or Mixed (4 triangle, 5 quadrilateral) */
    size_t ntri = 0, nflat = 0;
    for (size_t e = 0; e < m->nelem; e++)
        ntri += m->conn[4 * e + 3] < 0;
    int64_t *flat = malloc((5 * m->nelem + 1) * sizeof *flat);
    double *gx = malloc((2 * r->ngp + 1) * sizeof *gx), *gw = malloc((r->ngp + 1) * sizeof *gw),
           *ge = malloc((r->ngp + 1) * sizeof *ge);
    if (!flat || !gx || !gw || !ge) {
        free(flat), free(gx), free(gw), free(ge);
        return -1;
    }
    for (size_t e = 0; e < m->nelem; e++) {
        int nen = pk_fe2_elem_nodes(m, e);
        if (ntri && ntri < m->nelem)
            flat[nflat++] = nen == 3 ? 4 : 5;
        for (int a = 0; a < nen; a++)
            flat[nflat++] = m->conn[4 * e + a];
    }
    const char *kind = ntri == 0 ? "Quadrilateral" : ntri == m->nelem ? "Triangle" : "Mixed";
    rc |= pk_h5_write_array(h, "/observables/fe2/mesh/xdmf_topology", PK_H5_I64, 1, &nflat, flat,
                            NULL);
    rc |= pk_h5_obs_string(h, "fe2/mesh/xdmf_topology_type", kind);
    for (size_t g = 0; g < r->ngp; g++) {
        size_t e;
        pk_fe2_gauss_point(m, g, &gx[2 * g], &e, &gw[g]);
        ge[g] = (double)e;
    }
    size_t dg[2] = {r->ngp, 2};
    rc |= arr(h, "/observables/fe2/mesh/gauss_position", 2, dg, gx,
              pk_fe2_unit_of("fe2/mesh/gauss_position", u));
    rc |= arr(h, "/observables/fe2/mesh/gauss_weight", 1, &r->ngp, gw,
              pk_fe2_unit_of("fe2/mesh/gauss_weight", u));
    rc |= iarr(h, "/observables/fe2/mesh/gauss_element", ge, r->ngp);
    free(flat), free(gx), free(gw), free(ge);
    /* the load steps */
    rc |= iarr(h, "/observables/fe2/load_steps/step", r->step.v, r->nstep);
    rc |= arr(h, "/observables/fe2/load_steps/time", 1, &r->nstep, r->time.v, NULL);
    rc |= iarr(h, "/observables/fe2/load_steps/stage", r->stage.v, r->nstep);
    rc |= iarr(h, "/observables/fe2/load_steps/cuts", r->cuts.v, r->nstep);
    /* fields per converged step */
    const size_t n2[2] = {m->nnode, 2}, g4[2] = {r->ngp, 4}, g1[1] = {r->ngp}, e1[1] = {m->nelem},
                 b2[2] = {s->nbc, 2};
    rc |= series(h, r, clock, "displacement", NULL, &r->u, 2, n2, u);
    rc |= series(h, r, clock, "position", NULL, &r->x, 2, n2, u);
    rc |= series(h, r, clock, "deformation_gradient", NULL, &r->F, 2, g4, u);
    rc |= series(h, r, clock, "piola_stress", NULL, &r->P, 2, g4, u);
    rc |= series(h, r, clock, "cauchy_stress", NULL, &r->sigma, 2, g4, u);
    rc |= series(h, r, clock, "von_mises", NULL, &r->mises, 1, g1, u);
    rc |= series(h, r, clock, "von_mises_element", NULL, &r->mises_elem, 1, e1, u);
    rc |= series(h, r, clock, "rve/energy_density", NULL, &r->energy, 1, g1, u);
    rc |= series(h, r, clock, "rve/coordination", NULL, &r->coordination, 1, g1, u);
    rc |= series(h, r, clock, "rve/rattlers", NULL, &r->rattlers, 1, g1, u);
    rc |= series(h, r, clock, "rve/relaxation_iterations", NULL, &r->relax_iter, 1, g1, u);
    rc |= series(h, r, clock, "reaction", NULL, &r->reaction, 2, b2, u);
    rc |= series(h, r, clock, "area", NULL, &r->area, 0, NULL, u);
    rc |= series(h, r, clock, "dilatancy_percent", NULL, &r->dilatancy, 0, NULL, u);
    rc |= pk_h5_obs_double(h, "fe2/reference_area", r->area0,
                           pk_fe2_unit_of("fe2/reference_area", u));
    /* the names of the conditions (rows of reaction) */
    char names[4096] = "";
    for (size_t k = 0; k < s->nbc; k++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? "\n" : "",
                 s->bc[k].name);
    rc |= pk_h5_obs_string(h, "fe2/reaction/names", names);
    double comp[256];
    size_t nb = s->nbc < 256 ? s->nbc : 256;
    for (size_t k = 0; k < nb; k++)
        comp[k] = s->bc[k].type == PK_FE2_DISPLACEMENT ? s->bc[k].comp : -1;
    rc |= iarr(h, "/observables/fe2/reaction/component", comp, nb);
    for (size_t i = 0; i < r->nmicro && r->nstep; i++) {
        char name[64];
        snprintf(name, sizeof name, "micro/gauss_point_%zu", r->micro_gp[i]);
        pk_fe2_dbuf one = {0};
        for (size_t k = 0; !rc && k < r->nstep; k++)
            rc |= push(&one, &r->micro_x.v[((k * r->nmicro) + i) * 2 * r->ngrain], 2 * r->ngrain);
        const size_t dm[2] = {r->ngrain, 2};
        rc |= series(h, r, clock, name, "micro", &one, 2, dm, u);
        free(one.v);
    }
    /* the Newton histories: one row per solve (part of a load step), one
     * per residual norm */
    size_t np = r->part_step.n, ni = r->it_res.n;
    rc |= iarr(h, "/observables/fe2/newton/solves/step", r->part_step.v, np);
    rc |= arr(h, "/observables/fe2/newton/solves/t0", 1, &np, r->part_t0.v, NULL);
    rc |= arr(h, "/observables/fe2/newton/solves/t1", 1, &np, r->part_t1.v, NULL);
    rc |= iarr(h, "/observables/fe2/newton/solves/iterations", r->part_n.v, np);
    rc |= arr(h, "/observables/fe2/newton/solves/abs_residual_0", 1, &np, r->part_abs0.v,
              pk_fe2_unit_of("fe2/newton/solves/abs_residual_0", u));
    rc |= iarr(h, "/observables/fe2/newton/solves/converged", r->part_conv.v, np);
    rc |= iarr(h, "/observables/fe2/newton/iterations/solve", r->it_part.v, ni);
    rc |= arr(h, "/observables/fe2/newton/iterations/relative_residual", 1, &ni, r->it_res.v, NULL);
    rc |= arr(h, "/observables/fe2/newton/iterations/line_search", 1, &ni, r->it_eta.v, NULL);
    return rc ? -1 : 0;
}
