/* pack_place_tetfill.c — the 'tetfill' placer: Jerier's mesh filling
 * (core/tetfill/tetfill.h) of "domain": {"mesh": ...} or of a walled box (meshed by
 * core/mesh/mesh_box.c), with the job's "tetfill" options.  Sizes come from the
 * filler itself (only the radius range is prescribed): no grading. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/results/h5_result.h"
#include "api/mesh/mesh_io.h"
#include "pack_placer.h"
#include "core/tetfill/tetfill.h"
#include "core/tetfill/tetfill_stats.h"
#include "core/space/length_snap.h"

/* Kuhn cubes of edge h have mean unique-edge length (3 + 3√2 + √3)/7 · h. */
#define KUHN_MEAN_EDGE 1.2820

typedef struct tetfill_setup {
    pk_mesh mesh;
    pk_mesh_report rep;
    double origin[3]; /* mesh frame = particle frame + origin */
    /* The filler runs in units of r_min (core/space/length_snap.h): mesh and
     * prm in that unit, lengths snapped, so a job in any length unit computes
     * the same bits; the job's r_min and r_max in its own unit. */
    double ell, r_min, r_max;
    pk_tetfill_params prm;
    char unit[32]; /* the job's length unit */
} tetfill_setup;

static void preset(void *dst) { pk_tetfill_defaults(&((pk_tetfill_options *)dst)->prm); }

_Static_assert(sizeof(pk_tetfill_contact_rule) == sizeof(int), "named values are stored as int");
static const char *const contact_names[] = {"tangent", "touching",
                                            NULL}; /* pk_tetfill_contact_rule */
#define F(m) PK_OPT_FIELD(pk_tetfill_options, m)
static const pk_option tetfill_rows[] = {
    {"/tetfill/r_min", PK_OPT_NUMBER, F(r_min), PK_OPT_IMPLICIT},
    {"/tetfill/r_max", PK_OPT_NUMBER, F(r_max), PK_OPT_IMPLICIT},
    {"/tetfill/ratio", PK_OPT_NUMBER, F(ratio), PK_OPT_IMPLICIT},
    {"/tetfill/epsilon", PK_OPT_NUMBER, F(prm.eps), PK_OPT_PRESET},
    {"/tetfill/z_min", PK_OPT_INTEGER, F(prm.z_min), PK_OPT_PRESET, .lo = 2, .hi = 4},
    {"/tetfill/contact_rule", PK_OPT_ENUM, F(prm.contact_rule), PK_OPT_PRESET,
     .names = contact_names},
    {"/tetfill/vertex_weight", PK_OPT_NUMBER, F(prm.vertex_weight), PK_OPT_PRESET},
    {"/tetfill/loose", PK_OPT_BOOL, F(prm.skip_tet_loci), PK_OPT_PRESET},
    {"/tetfill/trim_after_loci", PK_OPT_BOOL, F(prm.trim_after_loci), PK_OPT_PRESET},
    {"/tetfill/densify", PK_OPT_BOOL, F(prm.densify), PK_OPT_PRESET},
    {"/tetfill/neighbours", PK_OPT_INTEGER, F(prm.neighbours), PK_OPT_PRESET, .lo = 4, .hi = 13},
    {"/tetfill/max_combos", PK_OPT_INTEGER, F(prm.max_combos), PK_OPT_PRESET, .lo = 1, .hi = 715},
    {"/tetfill/max_passes", PK_OPT_INTEGER, F(prm.max_passes), PK_OPT_PRESET, .lo = 0, .hi = 1000},
    {"/tetfill/max_tets", PK_OPT_INTEGER, F(max_tets), .dflt = 2000000, .lo = 1, .hi = 1e9},
};
#undef F
static const pk_option_table tetfill_options =
    PK_OPT_TABLE("pack.inputs.schema.json", pk_tetfill_options, tetfill_rows, preset);

/* Radii from r_min / r_max / ratio; ratio alone uses Jerier's mesh rule
 * r̄ = ℓ_mean / 8 (Jerier §2.2: r = ℓ/8 on an edge; the ratio rule of Jerier's
 * YADE code): r_min = 2 r̄/(R+1), r_max = 2 r̄ − r_min. */
static int radii(const pk_tetfill_options *o, double edge_mean, double *rmin, double *rmax)
{
    double a = o->r_min, b = o->r_max, R = o->ratio;
    if (a > 0 && b > 0) {
        *rmin = a;
        *rmax = b;
    } else if (R > 0 && a > 0) {
        *rmin = a;
        *rmax = R * a;
    } else if (R > 0 && b > 0) {
        *rmin = b / R;
        *rmax = b;
    } else if (R > 0 && edge_mean > 0) {
        double rbar = edge_mean / 8;
        *rmin = 2 * rbar / (R + 1);
        *rmax = 2 * rbar - *rmin;
    } else
        return -1;
    return *rmax >= *rmin ? 0 : -1;
}

/* The radii resolved in the job's unit → the filler's unit r_min. */
static void to_unit(tetfill_setup *S)
{
    S->ell = S->r_min = S->prm.r_min;
    S->r_max = S->prm.r_max;
    S->prm.r_min = 1;
    S->prm.r_max = pk_snap(S->r_max / S->ell);
}

/* Build the mesh and the parameters.  0, or -1 with a pointer and message. */
static int setup(const pk_pack_job *job, tetfill_setup *S, const char **ptr, const char **rule,
                 char *err, size_t errlen)
{
    memset(S, 0, sizeof *S);
    snprintf(S->unit, sizeof S->unit, "%s", job->unit);
    const pk_tetfill_options *o = &job->opt.tetfill;
    json_t *mesh = job->mesh;
    size_t max_tets = o->max_tets;
    pk_tetfill_params *prm = &S->prm;
    *prm = o->prm;
    *rule = "tetfill";
    if (job->dim != 3) {
        *ptr = "/dim";
        snprintf(err, errlen, "tetfill fills 3D domains (dim = 3)");
        return -1;
    }
    if (mesh) {
        *ptr = json_object_get(mesh, "file") ? "/domain/mesh/file" : "/domain/mesh";
        *rule = "mesh";
        if (pk_mesh_from_json(mesh, max_tets, &S->mesh, &S->rep, err, errlen) != 0)
            return -1;
        memcpy(S->origin, S->mesh.lo, sizeof S->origin);
        pk_mesh_translate(&S->mesh, S->origin);
        *rule = "radii";
        *ptr = "/tetfill";
        if (radii(o, S->mesh.edge_mean, &prm->r_min, &prm->r_max) != 0) {
            snprintf(err, errlen,
                     "give r_min and r_max, or the ratio R (with r_min, r_max, or "
                     "alone: r̄ = mean edge / 8), with r_max >= r_min");
            pk_mesh_free(&S->mesh);
            return -1;
        }
        /* Jerier's size rule ℓ ≈ 8 r̄: far off it, the direct spheres either
         * leave holes no sphere of the range can close or swallow each other */
        double ratio = S->mesh.edge_mean / (0.5 * (prm->r_min + prm->r_max));
        if (ratio < 4 || ratio > 16) {
            *rule = "meshScale";
            snprintf(err, errlen,
                     "the mesh's mean edge (%.4g) is %.3g mean radii; Jerier's method "
                     "needs about 8 (between 4 and 16): remesh, or give the ratio R alone",
                     S->mesh.edge_mean, ratio);
            pk_mesh_free(&S->mesh);
            return -1;
        }
        to_unit(S);
        for (size_t i = 0; i < 3 * S->mesh.nnode; i++)
            S->mesh.x[i] = pk_snap(S->mesh.x[i] / S->ell);
        pk_mesh_report again;
        *rule = "mesh";
        *ptr = json_object_get(mesh, "file") ? "/domain/mesh/file" : "/domain/mesh";
        if (pk_mesh_check(&S->mesh, max_tets, &again, err, errlen) != 0) {
            pk_mesh_free(&S->mesh);
            return -1;
        }
    } else {
        *ptr = "/tetfill";
        *rule = "radii";
        if (radii(o, 0, &prm->r_min, &prm->r_max) != 0) {
            snprintf(err, errlen,
                     "a box domain needs r_min or r_max (with r_max or ratio), "
                     "r_max >= r_min");
            return -1;
        }
        double lmin = fmin(job->box.L[0], fmin(job->box.L[1], job->box.L[2]));
        if (!(2 * prm->r_max <= lmin)) {
            snprintf(err, errlen,
                     "r_max = %g: the largest sphere must fit in the box (2 r_max <= %g)",
                     prm->r_max, lmin);
            return -1;
        }
        *ptr = "/domain/box/periodic";
        *rule = "walledBox";
        for (int k = 0; k < 3; k++)
            if (job->box.periodic[k]) {
                snprintf(err, errlen, "tetfill fills walled boxes (axis %d is periodic)", k);
                return -1;
            }
        *ptr = "/domain/box";
        *rule = "mesh";
        to_unit(S);
        double L[3]; /* inside the job's walls when mapped back */
        for (int k = 0; k < 3; k++)
            L[k] = pk_snap_within(job->box.L[k] / S->ell, S->ell, job->box.L[k]);
        double h = 8 * 0.5 * (prm->r_min + prm->r_max) / KUHN_MEAN_EDGE; /* ℓ ≈ 8 r̄ */
        /* a request's check only counts the tets: the worker meshes the box */
        if (job->service ? pk_mesh_box_count(L, h, max_tets, err, errlen) != 0
                         : pk_mesh_box(&S->mesh, L, h, max_tets, err, errlen) != 0)
            return -1;
    }
    prm->phi_target = job->has_phi ? job->phi : 0;
    prm->n_target = job->count;
    prm->seed = job->seed;
    prm->max_spheres = job->max_particles;
    return 0;
}

static json_t *ints_json(const int64_t *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(a, json_integer((json_int_t)v[i]));
    return a;
}

static json_t *reals_json(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *observables(const tetfill_setup *S, const pk_tetfill_stats *ts,
                           const pk_tetfill_measures *ms)
{
    const pk_tetfill_params *prm = &S->prm;
    const pk_mesh *m = &S->mesh;
    json_t *o = json_object();
    json_object_set_new(o, "r_min", json_real(S->r_min));
    json_object_set_new(o, "r_max", json_real(S->r_max));
    json_object_set_new(o, "ratio", json_real(S->r_max / S->r_min));
    json_object_set_new(o, "epsilon", json_real(prm->eps));
    json_object_set_new(o, "overlap_bound", json_real(prm->eps * S->r_min));
    json_object_set_new(o, "z_min", json_integer(prm->z_min));
    json_object_set_new(o, "count_direct", json_integer((json_int_t)ts->n_direct));
    json_object_set_new(o, "count_trimmed", json_integer((json_int_t)ts->n_trimmed));
    json_object_set_new(o, "count_geometric", json_integer((json_int_t)ts->n_geometric));
    json_object_set_new(o, "phi_geometric", json_real(ts->phi_geometric));
    json_object_set_new(o, "coordination_geometric", json_real(ts->geometric.z));
    json_object_set_new(o, "coordination_tangent_geometric", json_real(ts->geometric.z_tangent));
    json_object_set_new(o, "coordination_touching_geometric", json_real(ts->geometric.z_touching));
    json_object_set_new(o, "densify_passes", json_integer(ts->passes));
    json_object_set_new(o, "loci", json_integer((json_int_t)ts->loci));
    json_object_set_new(o, "solves", json_integer((json_int_t)ts->solves));
    json_object_set_new(o, "singular_quadruples", json_integer((json_int_t)ts->singular));
    json_object_set_new(o, "accepted_four", json_integer((json_int_t)ts->accepted));
    json_object_set_new(o, "accepted_three", json_integer((json_int_t)ts->accepted_three));
    json_object_set_new(o, "seconds_geometric", json_real(ts->seconds_geometric));
    json_object_set_new(o, "overlap_max_relative", json_real(ms->overlap_max));
    json_object_set_new(o, "overlap_mean_relative", json_real(ms->overlap_mean));
    json_object_set_new(o, "pairs_overlapping", json_integer((json_int_t)ms->pairs_overlapping));
    json_object_set_new(o, "pairs_over_bound", json_integer((json_int_t)ms->pairs_over_bound));
    json_object_set_new(o, "contacts", json_integer((json_int_t)ms->contacts));
    json_object_set_new(o, "coordination_mean", json_real(ms->z_mean));
    json_object_set_new(o, "coordination_tangent", json_real(ms->z_tangent));
    json_object_set_new(o, "coordination_touching", json_real(ms->z_touching));
    json_object_set_new(o, "coordination_histogram", ints_json(ms->z_hist, PK_TETFILL_ZHIST));
    json_object_set_new(o, "fabric", reals_json(ms->fabric, 9));
    json_object_set_new(o, "fabric_eigenvalues", reals_json(ms->fabric_eig, 3));
    json_object_set_new(o, "phi", json_real(ms->phi));
    json_object_set_new(o, "region_ids", ints_json(ms->region_id, ms->nregion));
    json_object_set_new(o, "region_phi", reals_json(ms->region_phi, ms->nregion));
    json_object_set_new(o, "spheres_per_tet_mean", json_real(ms->spheres_per_tet_mean));
    json_object_set_new(o, "spheres_per_tet_histogram", ints_json(ms->t_hist, PK_TETFILL_THIST));
    json_object_set_new(o, "centres_outside_mesh", json_integer((json_int_t)ms->outside));
    json_object_set_new(o, "min_boundary_clearance_relative",
                        json_real(isfinite(ms->min_wall_clearance) ? ms->min_wall_clearance : -1));
    json_object_set_new(o, "mesh_nodes_count", json_integer((json_int_t)m->nnode));
    json_object_set_new(o, "mesh_tets_count", json_integer((json_int_t)m->ntet));
    json_object_set_new(o, "mesh_boundary_faces", json_integer((json_int_t)m->nbface));
    json_object_set_new(o, "mesh_volume", json_real(m->volume * S->ell * S->ell * S->ell));
    json_object_set_new(o, "mesh_edge_mean", json_real(m->edge_mean * S->ell));
    json_object_set_new(o, "mesh_reoriented", json_integer((json_int_t)S->rep.reoriented));
    json_object_set_new(o, "mesh_slivers", json_integer((json_int_t)S->rep.slivers));
    json_object_set_new(o, "mesh_first_sliver",
                        json_integer(S->rep.slivers ? (json_int_t)S->rep.first_sliver : -1));
    json_object_set_new(o, "mesh_origin", reals_json(S->origin, 3));
    return o;
}

/* The mesh as filled, in the particles' frame: mesh_nodes [nnode][3] (the
 * job's length unit), mesh_tets [ntet][4] (0-based), mesh_regions [ntet]. */
static int write_mesh(pk_h5 *h, const char *prefix, void *extra)
{
    const tetfill_setup *S = extra;
    const pk_mesh *m = &S->mesh;
    char name[128];
    int64_t *t = malloc(4 * m->ntet * sizeof *t);
    double *x = malloc(3 * m->nnode * sizeof *x);
    if (!t || !x) {
        free(t);
        free(x);
        return -1;
    }
    int rc = 0;
    size_t dn[2] = {m->nnode, 3}, dt[2] = {m->ntet, 4};
    for (size_t i = 0; i < 3 * m->nnode; i++)
        x[i] = m->x[i] * S->ell;
    snprintf(name, sizeof name, "/observables/%s/mesh_nodes", prefix);
    pk_h5_write_array(h, name, PK_H5_F64, 2, dn, x, S->unit);
    free(x);
    for (size_t i = 0; i < 4 * m->ntet; i++)
        t[i] = m->t[i];
    snprintf(name, sizeof name, "/observables/%s/mesh_tets", prefix);
    pk_h5_write_array(h, name, PK_H5_I64, 2, dt, t, NULL);
    for (size_t i = 0; i < m->ntet; i++)
        t[i] = m->region[i];
    snprintf(name, sizeof name, "%s/mesh_regions", prefix);
    pk_h5_obs_ints(h, name, t, m->ntet);
    free(t);
    return rc;
}

static void free_setup(void *extra)
{
    tetfill_setup *S = extra;
    pk_mesh_free(&S->mesh);
    free(S);
}

/* The mesh read (or the box meshed) and the radii checked; kept for the run
 * in *prepared when given (read once). */
static void check_tetfill(const pk_pack_job *job, const pk_pack_plan *plan, void **prepared,
                          pk_schema_errors *errs)
{
    (void)plan;
    const char *ptr, *rule;
    char err[512];
    if (job->service && json_object_get(job->mesh, "file"))
        return; /* a request to the daemon: the worker reads and checks the file */
    tetfill_setup *S = malloc(sizeof *S);
    if (!S) {
        pk_schema_errors_add(errs, "/tetfill", "memory", "out of memory");
        return;
    }
    if (setup(job, S, &ptr, &rule, err, sizeof err) != 0) {
        pk_schema_errors_add(errs, ptr, rule, "%s", err);
        free_setup(S); /* a box meshed before its check failed */
    } else if (prepared && !job->service)
        *prepared = S;
    else
        free_setup(S);
}

static int place_tetfill(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                         const pk_run_ctx *run, pk_particles *p, pk_place_stats *st, char *err,
                         size_t errlen)
{
    pk_monitor *mon = run->mon;
    (void)sz;
    tetfill_setup *S = plan->prepared; /* the check's, or built here */
    const int own = !S;
    const char *ptr, *rule;
    if (own && !(S = malloc(sizeof *S))) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (own && setup(job, S, &ptr, &rule, err, errlen) != 0) {
        free_setup(S);
        return -1;
    }
    pk_tetfill_stats ts;
    if (pk_tetfill(&S->mesh, &S->prm, mon, p, &ts) != 0) {
        snprintf(err, errlen, "tet filling failed (%s)", pk_stop_reason_name(ts.reason));
        if (own)
            free_setup(S);
        return -1;
    }
    pk_tetfill_measures ms;
    if (pk_tetfill_measure(&S->mesh, p, S->prm.r_min, S->prm.eps, &ms) != 0) {
        snprintf(err, errlen, "out of memory measuring the packing");
        if (own)
            free_setup(S);
        return -1;
    }
    const double ell = S->ell; /* back to the job's unit */
    for (size_t i = 0; i < p->n; i++) {
        for (int k = 0; k < 3; k++)
            p->x[3 * i + k] *= ell;
        p->r[i] *= ell;
    }
    *st = (pk_place_stats){.reason = ts.reason,
                           .placed = p->n,
                           .requested = job->count,
                           .seconds = ts.seconds,
                           .has_domain = 1,
                           .domain_measure = job->mesh ? S->mesh.volume * ell * ell * ell
                                                       : pk_box_measure(&job->box),
                           .overlap_tol = S->prm.eps * S->r_min,
                           .extra = S,
                           .write_extra = write_mesh,
                           .free_extra = own ? free_setup : NULL};
    st->domain_box.dim = 3;
    for (int k = 0; k < 3; k++) /* the job's walls, or the mesh's bounding box */
        st->domain_box.L[k] = job->mesh ? S->mesh.hi[k] * ell : job->box.L[k];
    st->obs = observables(S, &ts, &ms);
    pk_tetfill_measures_free(&ms);
    return 0;
}

/* Its observables with a unit. */
static const pk_unit_row tetfill_units[] = {
    {"r_min", PK_U_LENGTH},
    {"r_max", PK_U_LENGTH},
    {"overlap_bound", PK_U_LENGTH},
    {"mesh_volume", PK_U_VOLUME},
    {"mesh_edge_mean", PK_U_LENGTH},
    {"mesh_origin", PK_U_LENGTH},
    {"seconds_geometric", PK_U_SECONDS},
    {NULL, PK_U_NONE},
};

const pk_placer pk_placer_tetfill = {.name = "tetfill",
                                     .fills_mesh = 1,
                                     .units = tetfill_units,
                                     .own_sizes = 1,
                                     .options = &tetfill_options,
                                     .check = check_tetfill,
                                     .release = free_setup,
                                     .place = place_tetfill};
