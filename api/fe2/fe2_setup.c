/* fe2_setup.c — an fe2 job's macro problem: the mesh (rectangle, inline,
 * Gmsh) with its named sets, the boundary conditions resolved to degrees of
 * freedom and unit load vectors, the stages' end values, and the checks
 * that name the field at fault (docs/job-format.md, fe2). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fe2_job.h"

static const char *const type_names[] = {"displacement", "pressure", "traction",
                                         "force",        "gravity",  NULL};

/* The four edges and corners of an nx × ny rectangle (node j·(nx+1) + i,
 * fe2_mesh.h), each edge's sides in order. */
static int rectangle_sets(pk_mesh2d *m, size_t nx, size_t ny)
{
    static const char *const edge[] = {"bottom", "right", "top", "left"};
    const size_t w = nx + 1;
    for (int k = 0; k < 4; k++) {
        size_t n = k % 2 ? ny : nx;
        pk_mesh2d_set *s = pk_mesh2d_add_set(m, edge[k]);
        if (!s || !(s->node = malloc((n + 1) * sizeof *s->node)) ||
            !(s->edge = malloc(2 * n * sizeof *s->edge)))
            return -1;
        for (size_t i = 0; i <= n; i++) {
            size_t v = k == 0 ? i : k == 1 ? i * w + nx : k == 2 ? ny * w + i : i * w;
            s->node[s->nnode++] = (int32_t)v;
            if (i)
                s->edge[2 * s->nedge] = s->node[i - 1], s->edge[2 * s->nedge++ + 1] = (int32_t)v;
        }
    }
    static const char *const corner[] = {"lower_left", "lower_right", "upper_left", "upper_right"};
    const size_t cv[4] = {0, nx, ny * w, ny * w + nx};
    for (int k = 0; k < 4; k++) {
        pk_mesh2d_set *s = pk_mesh2d_add_set(m, corner[k]);
        if (!s || !(s->node = malloc(sizeof *s->node)))
            return -1;
        s->node[s->nnode++] = (int32_t)cv[k];
    }
    return 0;
}

/* An inline mesh's nodes, elements and sets (indices checked). */
static void inline_mesh(json_t *j, pk_mesh2d *m, pk_schema_errors *errs)
{
    json_t *nodes = json_object_get(j, "nodes"), *elems = json_object_get(j, "elements");
    m->nnode = json_array_size(nodes);
    m->nelem = json_array_size(elems);
    m->xy = malloc(2 * m->nnode * sizeof *m->xy);
    m->conn = malloc(4 * m->nelem * sizeof *m->conn);
    if (!m->xy || !m->conn) {
        pk_schema_errors_add(errs, "/mesh", "memory", "out of memory for the mesh");
        return;
    }
    for (size_t i = 0; i < m->nnode; i++)
        for (size_t c = 0; c < 2; c++)
            m->xy[2 * i + c] = json_number_value(json_array_get(json_array_get(nodes, i), c));
    for (size_t e = 0; e < m->nelem; e++) {
        json_t *el = json_array_get(elems, e);
        for (size_t a = 0; a < 4; a++) {
            long long v = -1;
            if (a < json_array_size(el))
                pk_json_int(json_array_get(el, a), &v);
            m->conn[4 * e + a] = (int32_t)v;
            if (a < json_array_size(el) && (v < 0 || (size_t)v >= m->nnode)) {
                char ptr[80];
                snprintf(ptr, sizeof ptr, "/mesh/elements/%zu/%zu", e, a);
                pk_schema_errors_add(errs, ptr, "mesh", "node %lld: the mesh has %zu nodes", v,
                                     m->nnode);
                return;
            }
        }
    }
    const char *name;
    json_t *set;
    json_object_foreach (json_object_get(j, "sets"), name, set) {
        if (strlen(name) > 63) {
            pk_schema_errors_add(errs, "/mesh/sets", "semantic",
                                 "set name \"%.40s...\" is longer than 63 characters", name);
            return;
        }
        pk_mesh2d_set *s = pk_mesh2d_add_set(m, name);
        json_t *sn = json_object_get(set, "nodes"), *se = json_object_get(set, "edges");
        size_t nn = json_array_size(sn), ne = json_array_size(se);
        if (!s || !(s->node = malloc((nn + 2 * ne + 1) * sizeof *s->node)) ||
            !(s->edge = malloc((2 * ne + 1) * sizeof *s->edge))) {
            pk_schema_errors_add(errs, "/mesh/sets", "memory", "out of memory");
            return;
        }
        for (size_t i = 0; i < nn + 2 * ne; i++) {
            json_t *v = i < nn ? json_array_get(sn, i)
                               : json_array_get(json_array_get(se, (i - nn) / 2), (i - nn) % 2);
            long long x = json_integer_value(v);
            if (x < 0 || (size_t)x >= m->nnode) {
                char ptr[160];
                if (i < nn)
                    snprintf(ptr, sizeof ptr, "/mesh/sets/%s/nodes/%zu", name, i);
                else
                    snprintf(ptr, sizeof ptr, "/mesh/sets/%s/edges/%zu", name, (i - nn) / 2);
                pk_schema_errors_add(errs, ptr, "mesh", "node %lld: the mesh has %zu nodes", x,
                                     m->nnode);
                return;
            }
            s->node[s->nnode++] = (int32_t)x;
            if (i >= nn)
                s->edge[i - nn] = (int32_t)x;
        }
        s->nedge = ne;
        pk_mesh2d_set_finish(s);
    }
}

/* Gauss points of the elements as given (3 nodes: 1, 4 nodes: 4). */
static size_t gauss_of(const int32_t *conn, size_t nelem)
{
    size_t n = 0;
    for (size_t e = 0; e < nelem; e++)
        n += conn[4 * e + 3] < 0 ? 1 : 4;
    return n;
}

static int build_mesh(const pk_fe2_job *job, pk_fe2_setup *s, pk_schema_errors *errs)
{
    json_t *j = job->mesh, *rect = json_object_get(j, "rectangle");
    const char *file = json_string_value(json_object_get(j, "file"));
    char err[600];
    size_t before = errs->n;
    if (rect) {
        json_t *size = json_object_get(rect, "size"), *el = json_object_get(rect, "elements");
        size_t nx = (size_t)json_integer_value(json_array_get(el, 0)),
               ny = (size_t)json_integer_value(json_array_get(el, 1));
        if (4 * nx * ny > job->max_gauss_points) {
            pk_schema_errors_add(errs, "/mesh/rectangle/elements", "limit",
                                 "%zu × %zu Q1 elements have %zu Gauss points: over "
                                 "limits.max_gauss_points %zu",
                                 nx, ny, 4 * nx * ny, job->max_gauss_points);
            return -1;
        }
        if (pk_fe2_mesh_rectangle(json_number_value(json_array_get(size, 0)),
                                  json_number_value(json_array_get(size, 1)), nx, ny,
                                  &s->mesh) != 0 ||
            rectangle_sets(&s->sets, nx, ny) != 0) {
            pk_schema_errors_add(errs, "/mesh", "memory", "out of memory for the mesh");
            return -1;
        }
        s->sets.nnode = s->mesh.nnode;
        s->sets.nelem = s->mesh.nelem;
    } else {
        if (file) {
            if (pk_mesh2d_read_msh(file, job->max_gauss_points, &s->sets, err, sizeof err) != 0) {
                pk_schema_errors_add(errs, "/mesh/file", "mesh", "%s", err);
                return -1;
            }
        } else {
            json_t *el = json_object_get(j, "elements");
            size_t ngp = 0;
            for (size_t e = 0; e < json_array_size(el); e++)
                ngp += json_array_size(json_array_get(el, e)) == 3 ? 1 : 4;
            if (ngp > job->max_gauss_points) {
                pk_schema_errors_add(errs, "/mesh/elements", "limit",
                                     "%zu Gauss points: over limits.max_gauss_points %zu", ngp,
                                     job->max_gauss_points);
                return -1;
            }
            inline_mesh(j, &s->sets, errs);
            if (errs->n != before)
                return -1;
        }
        size_t ngp = gauss_of(s->sets.conn, s->sets.nelem);
        if (ngp > job->max_gauss_points) {
            pk_schema_errors_add(errs, "/mesh", "limit",
                                 "%zu Gauss points: over limits.max_gauss_points %zu", ngp,
                                 job->max_gauss_points);
            return -1;
        }
        s->mesh.nnode = s->sets.nnode;
        s->mesh.nelem = s->sets.nelem;
        s->mesh.xy = s->sets.xy;
        s->mesh.conn = s->sets.conn;
        s->sets.xy = NULL;
        s->sets.conn = NULL;
    }
    if (pk_fe2_mesh_finish(&s->mesh, err, sizeof err) != 0) {
        pk_schema_errors_add(errs, file ? "/mesh/file" : "/mesh", "mesh", "%s", err);
        return -1;
    }
    if (!pk_mesh2d_find(&s->sets, "all")) {
        pk_mesh2d_set *all = pk_mesh2d_add_set(&s->sets, "all");
        if (!all || !(all->node = malloc((s->mesh.nnode + 1) * sizeof *all->node))) {
            pk_schema_errors_add(errs, "/mesh", "memory", "out of memory");
            return -1;
        }
        for (size_t i = 0; i < s->mesh.nnode; i++)
            all->node[all->nnode++] = (int32_t)i;
    }
    s->ndof = 2 * s->mesh.nnode;
    return 0;
}

/* The outward unit normal of the side a–b of a (counter-clockwise) element;
 * −1 when no element has that side. */
static int side_normal(const pk_fe2_mesh *m, int32_t a, int32_t b, double n[2])
{
    for (size_t e = 0; e < m->nelem; e++) {
        int nen = pk_fe2_elem_nodes(m, e);
        for (int i = 0; i < nen; i++) {
            int32_t p = m->conn[4 * e + i], q = m->conn[4 * e + (i + 1) % nen];
            if ((p == a && q == b) || (p == b && q == a)) {
                double dx = m->xy[2 * q] - m->xy[2 * p], dy = m->xy[2 * q + 1] - m->xy[2 * p + 1];
                double l = hypot(dx, dy);
                n[0] = dy / l; /* right of p → q, the outside of a CCW element */
                n[1] = -dx / l;
                return 0;
            }
        }
    }
    return -1;
}

/* The unit load vectors of condition k (loads only). */
static int unit_loads(pk_fe2_setup *s, size_t k, const char *ptr, pk_schema_errors *errs)
{
    pk_fe2_bc *b = &s->bc[k];
    const pk_fe2_mesh *m = &s->mesh;
    int nc = b->type == PK_FE2_PRESSURE ? 1 : 2;
    for (int c = 0; c < nc; c++)
        if (!(b->unit[c] = calloc(s->ndof, sizeof *b->unit[c]))) {
            pk_schema_errors_add(errs, ptr, "memory", "out of memory");
            return -1;
        }
    if (b->type == PK_FE2_PRESSURE || b->type == PK_FE2_TRACTION) {
        if (!b->set->nedge) {
            pk_schema_errors_add(errs, ptr, "edges",
                                 "set \"%s\" has no edges: a %s acts on element sides (a line "
                                 "group of a Gmsh file, an edge of the rectangle, or \"edges\" "
                                 "of an inline set)",
                                 b->set->name, type_names[b->type]);
            return -1;
        }
        for (size_t i = 0; i < b->set->nedge; i++) {
            int32_t a = b->set->edge[2 * i], c2 = b->set->edge[2 * i + 1];
            double n[2];
            if (side_normal(m, a, c2, n) != 0) {
                pk_schema_errors_add(errs, ptr, "edges",
                                     "edge %d–%d of set \"%s\" is no side of an element", a, c2,
                                     b->set->name);
                return -1;
            }
            if (b->type == PK_FE2_PRESSURE) { /* t = −p n */
                const double t[2] = {-n[0], -n[1]};
                pk_fe2_edge_traction(m, a, c2, t, b->unit[0]);
            } else
                for (int c = 0; c < 2; c++) {
                    const double t[2] = {c == 0, c == 1};
                    pk_fe2_edge_traction(m, a, c2, t, b->unit[c]);
                }
        }
    } else if (b->type == PK_FE2_FORCE) {
        for (size_t i = 0; i < b->set->nnode; i++)
            for (int c = 0; c < 2; c++)
                b->unit[c][2 * (size_t)b->set->node[i] + c] += 1.0 / (double)b->set->nnode;
    } else
        for (int c = 0; c < 2; c++) {
            const double g[2] = {c == 0 ? b->density : 0, c == 1 ? b->density : 0};
            pk_fe2_body_force(m, g, b->unit[c]);
        }
    return 0;
}

static int cmp_fix(const void *x, const void *y)
{
    const int32_t *a = x, *b = y; /* (dof, bc) */
    return a[0] != b[0] ? (a[0] > b[0]) - (a[0] < b[0]) : (a[1] > b[1]) - (a[1] < b[1]);
}

/* The prescribed dofs, each once; a dof of two displacements that differ
 * at some stage is a conflict. */
static int fixed_dofs(pk_fe2_setup *s, pk_schema_errors *errs)
{
    size_t n = 0;
    for (size_t k = 0; k < s->nbc; k++)
        if (s->bc[k].type == PK_FE2_DISPLACEMENT)
            n += s->bc[k].set->nnode;
    int32_t *pair = malloc((2 * n + 2) * sizeof *pair);
    s->fix_dof = malloc((n + 1) * sizeof *s->fix_dof);
    s->fix_bc = malloc((n + 1) * sizeof *s->fix_bc);
    if (!pair || !s->fix_dof || !s->fix_bc) {
        free(pair);
        pk_schema_errors_add(errs, "/boundary_conditions", "memory", "out of memory");
        return -1;
    }
    size_t p = 0;
    for (size_t k = 0; k < s->nbc; k++)
        if (s->bc[k].type == PK_FE2_DISPLACEMENT)
            for (size_t i = 0; i < s->bc[k].set->nnode; i++) {
                pair[2 * p] = 2 * s->bc[k].set->node[i] + s->bc[k].comp;
                pair[2 * p++ + 1] = (int32_t)k;
            }
    qsort(pair, p, 2 * sizeof *pair, cmp_fix);
    int rc = 0;
    for (size_t i = 0; i < p; i++) {
        if (i && pair[2 * i] == pair[2 * i - 2]) {
            size_t a = (size_t)s->fix_bc[s->nfix - 1], b = (size_t)pair[2 * i + 1];
            for (size_t st = 0; !rc && st <= s->nstage; st++)
                if (s->value[(st * s->nbc + a) * 2] != s->value[(st * s->nbc + b) * 2]) {
                    char ptr[64];
                    snprintf(ptr, sizeof ptr, "/boundary_conditions/%zu", b);
                    pk_schema_errors_add(
                        errs, ptr, "conflict",
                        "node %d, component %c: prescribed by \"%s\" and \"%s\" with different "
                        "values (%g and %g %s); give both the same targets or leave the node "
                        "out of one set",
                        pair[2 * i] / 2, "xy"[pair[2 * i] % 2], s -> bc[a].name, s->bc[b].name,
                        s->value[(st * s->nbc + a) * 2], s->value[(st * s->nbc + b) * 2],
                        st ? "at the end of a stage" : "initially");
                    rc = -1;
                }
            continue;
        }
        s->fix_dof[s->nfix] = pair[2 * i];
        s->fix_bc[s->nfix++] = pair[2 * i + 1];
    }
    free(pair);
    return rc;
}

static int is_fixed(const pk_fe2_setup *s, int32_t dof)
{
    size_t lo = 0, hi = s->nfix;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (s->fix_dof[mid] < dof)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < s->nfix && s->fix_dof[lo] == dof;
}

/* A load whose every non-zero nodal force sits on a prescribed dof. */
static void load_on_prescribed(const pk_fe2_setup *s, pk_schema_errors *errs)
{
    for (size_t k = 0; k < s->nbc; k++) {
        const pk_fe2_bc *b = &s->bc[k];
        for (int c = 0; b->type != PK_FE2_DISPLACEMENT && c < PK_FE2_BC_VALUES(b->type); c++) {
            int used = 0, free_dof = 0, any = 0;
            for (size_t st = 1; st <= s->nstage; st++)
                used |= s->value[(st * s->nbc + k) * 2 + (size_t)c] != 0;
            for (size_t d = 0; used && d < s->ndof; d++)
                if (b->unit[c][d] != 0) {
                    any = 1;
                    free_dof |= !is_fixed(s, (int32_t)d);
                }
            if (used && any && !free_dof) {
                char ptr[64];
                snprintf(ptr, sizeof ptr, "/boundary_conditions/%zu", k);
                pk_schema_errors_add(errs, ptr, "loadOnPrescribed",
                                     "the %s \"%s\"%s acts only on prescribed degrees of freedom: "
                                     "it would go to the reactions unseen",
                                     type_names[b->type], b->name,
                                     b->type == PK_FE2_PRESSURE ? ""
                                         : c                    ? " (y)"
                                                                : " (x)");
            }
        }
    }
}

/* Stage values: start at 0, each stage's targets replace them. */
static int stage_values(const pk_fe2_job *job, pk_fe2_setup *s, pk_schema_errors *errs)
{
    size_t before = errs->n;
    for (size_t st = 0; st < s->nstage; st++) {
        json_t *stage = json_array_get(job->stages, st), *v;
        s->increments[st] = (size_t)json_integer_value(json_object_get(stage, "increments"));
        snprintf(s->stage_name[st], sizeof s->stage_name[0], "%s",
                 json_string_value(json_object_get(stage, "name"))
                     ? json_string_value(json_object_get(stage, "name"))
                     : "");
        double *to = &s->value[(st + 1) * s->nbc * 2];
        memcpy(to, to - s->nbc * 2, s->nbc * 2 * sizeof *to);
        const char *name;
        json_object_foreach (json_object_get(stage, "targets"), name, v) {
            char ptr[200];
            snprintf(ptr, sizeof ptr, "/stages/%zu/targets/%s", st, name);
            size_t k = 0;
            while (k < s->nbc && strcmp(s->bc[k].name, name))
                k++;
            if (k == s->nbc) {
                pk_schema_errors_add(errs, ptr, "target", "no boundary condition is named \"%s\"",
                                     name);
                continue;
            }
            int nv = PK_FE2_BC_VALUES(s->bc[k].type);
            if (nv == 1 ? !json_is_number(v) : !json_is_array(v)) {
                pk_schema_errors_add(errs, ptr, "target", "a %s takes %s",
                                     type_names[s->bc[k].type],
                                     nv == 1 ? "a number" : "a vector [x, y]");
                continue;
            }
            for (int c = 0; c < nv; c++)
                to[2 * k + (size_t)c] = nv == 1 ? json_number_value(v)
                                                : json_number_value(json_array_get(v, (size_t)c));
        }
    }
    return errs->n == before ? 0 : -1;
}

size_t pk_fe2_setup_build(const pk_fe2_job *job, pk_fe2_setup *s, pk_schema_errors *errs)
{
    size_t before = errs->n;
    memset(s, 0, sizeof *s);
    if (build_mesh(job, s, errs) != 0)
        return errs->n - before;
    s->nbc = json_array_size(job->bcs);
    s->nstage = json_array_size(job->stages);
    s->bc = calloc(s->nbc + 1, sizeof *s->bc);
    s->value = calloc((s->nstage + 1) * (s->nbc + 1) * 2, sizeof *s->value);
    s->increments = calloc(s->nstage + 1, sizeof *s->increments);
    s->stage_name = calloc(s->nstage + 1, sizeof *s->stage_name);
    if (!s->bc || !s->value || !s->increments || !s->stage_name) {
        pk_schema_errors_add(errs, "", "memory", "out of memory");
        return errs->n - before;
    }
    for (size_t k = 0; k < s->nbc; k++) {
        json_t *b = json_array_get(job->bcs, k);
        pk_fe2_bc *bc = &s->bc[k];
        char ptr[64];
        snprintf(ptr, sizeof ptr, "/boundary_conditions/%zu", k);
        snprintf(bc->name, sizeof bc->name, "%s", json_string_value(json_object_get(b, "name")));
        const char *type = json_string_value(json_object_get(b, "type"));
        for (int t = 0; type_names[t]; t++)
            if (!strcmp(type, type_names[t]))
                bc->type = (pk_fe2_bc_type)t;
        bc->comp = !strcmp(json_string_value(json_object_get(b, "component"))
                               ? json_string_value(json_object_get(b, "component"))
                               : "x",
                           "y");
        bc->density = json_number_value(json_object_get(b, "density"));
        for (size_t i = 0; i < k; i++)
            if (!strcmp(s->bc[i].name, bc->name))
                pk_schema_errors_add(errs, ptr, "unique",
                                     "the name \"%s\" is taken by boundary condition %zu", bc->name,
                                     i);
        const char *on = json_string_value(json_object_get(b, "on"));
        if (bc->type != PK_FE2_GRAVITY && !(bc->set = pk_mesh2d_find(&s->sets, on))) {
            char names[200] = "";
            for (size_t i = 0; i < s->sets.nset && strlen(names) < 150; i++)
                snprintf(names + strlen(names), sizeof names - strlen(names), "%s\"%s\"",
                         i ? ", " : "", s->sets.set[i].name);
            snprintf(ptr, sizeof ptr, "/boundary_conditions/%zu/on", k);
            pk_schema_errors_add(errs, ptr, "set", "the mesh has no set \"%s\" (its sets: %s)", on,
                                 names);
            continue;
        }
        if (bc->type != PK_FE2_DISPLACEMENT && unit_loads(s, k, ptr, errs) != 0)
            continue;
    }
    if (errs->n != before || stage_values(job, s, errs) != 0 || fixed_dofs(s, errs) != 0)
        return errs->n - before;
    load_on_prescribed(s, errs);
    return errs->n - before;
}

void pk_fe2_setup_targets(const pk_fe2_setup *s, size_t k, double t, double *uD, double *fext)
{
    const double *a = &s->value[k * s->nbc * 2], *b = a + s->nbc * 2;
    for (size_t i = 0; i < s->nfix; i++) {
        size_t j = 2 * (size_t)s->fix_bc[i];
        uD[i] = a[j] + t * (b[j] - a[j]);
    }
    memset(fext, 0, s->ndof * sizeof *fext);
    for (size_t j = 0; j < s->nbc; j++)
        for (int c = 0; s->bc[j].type != PK_FE2_DISPLACEMENT && c < PK_FE2_BC_VALUES(s->bc[j].type);
             c++) {
            double v = a[2 * j + (size_t)c] + t * (b[2 * j + (size_t)c] - a[2 * j + (size_t)c]);
            for (size_t d = 0; v != 0 && d < s->ndof; d++)
                fext[d] += v * s->bc[j].unit[c][d];
        }
}

void pk_fe2_setup_free(pk_fe2_setup *s)
{
    for (size_t k = 0; s->bc && k < s->nbc; k++)
        free(s->bc[k].unit[0]), free(s->bc[k].unit[1]);
    free(s->bc);
    free(s->fix_dof);
    free(s->fix_bc);
    free(s->value);
    free(s->increments);
    free(s->stage_name);
    pk_mesh2d_free(&s->sets);
    pk_fe2_mesh_free(&s->mesh);
    memset(s, 0, sizeof *s);
}
