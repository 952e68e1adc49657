/* mesh_io.c — read tet meshes: inline JSON, Gmsh MSH 2.2 / 4.1 ASCII, TetGen. */
#include "mesh_io.h"
#include "api/schemas/json_schema.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/inputs/input_open.h"

/* ---- a whitespace tokenizer with line numbers ('#' comments for TetGen) */
typedef struct reader {
    FILE *f;
    const char *path;
    long line;
    int hash_comments;
    char tok[128];
} reader;

static const char *next_tok(reader *r)
{
    int c;
    for (;;) {
        c = getc(r->f);
        if (c == EOF)
            return NULL;
        if (c == '\n')
            r->line++;
        else if (c == '#' && r->hash_comments) {
            while ((c = getc(r->f)) != EOF && c != '\n')
                ;
            if (c == EOF)
                return NULL;
            r->line++;
        } else if (!isspace(c))
            break;
    }
    size_t n = 0;
    while (c != EOF && !isspace(c)) {
        if (n + 1 < sizeof r->tok)
            r->tok[n++] = (char)c;
        c = getc(r->f);
    }
    if (c == '\n')
        ungetc(c, r->f);
    r->tok[n] = 0;
    return r->tok;
}

static int next_num(reader *r, double *v, char *err, size_t errlen)
{
    char *end;
    if (next_tok(r)) {
        *v = strtod(r->tok, &end);
        if (*end == 0 && isfinite(*v))
            return 0;
    }
    snprintf(err, errlen, "%s:%ld: expected a number, got \"%s\"", r->path, r->line + 1,
             feof(r->f) ? "end of file" : r->tok);
    return -1;
}

static int next_int(reader *r, long long *v, char *err, size_t errlen)
{
    char *end;
    if (next_tok(r)) {
        *v = strtoll(r->tok, &end, 10);
        if (*end == 0)
            return 0;
    }
    snprintf(err, errlen, "%s:%ld: expected an integer, got \"%s\"", r->path, r->line + 1,
             feof(r->f) ? "end of file" : r->tok);
    return -1;
}

/* ---- growing node / tet lists keyed by file tags */
typedef struct raw_mesh {
    size_t nn, ncap, nt, tcap;
    long long *ntag;
    double *x;
    long long *t; /* [nt][4] node tags */
    int32_t *region;
} raw_mesh;

static void raw_free(raw_mesh *w)
{
    free(w->ntag);
    free(w->x);
    free(w->t);
    free(w->region);
}

static int raw_node(raw_mesh *w, long long tag, const double x[3])
{
    if (w->nn == w->ncap) {
        size_t cap = w->ncap ? 2 * w->ncap : 1024;
        long long *a = realloc(w->ntag, cap * sizeof *a);
        if (!a)
            return -1;
        w->ntag = a;
        double *b = realloc(w->x, 3 * cap * sizeof *b);
        if (!b)
            return -1;
        w->x = b;
        w->ncap = cap;
    }
    w->ntag[w->nn] = tag;
    memcpy(&w->x[3 * w->nn++], x, 3 * sizeof *x);
    return 0;
}

static int raw_tet(raw_mesh *w, const long long v[4], int32_t region)
{
    if (w->nt == w->tcap) {
        size_t cap = w->tcap ? 2 * w->tcap : 1024;
        long long *a = realloc(w->t, 4 * cap * sizeof *a);
        if (!a)
            return -1;
        w->t = a;
        int32_t *b = realloc(w->region, cap * sizeof *b);
        if (!b)
            return -1;
        w->region = b;
        w->tcap = cap;
    }
    memcpy(&w->t[4 * w->nt], v, 4 * sizeof *v);
    w->region[w->nt++] = region;
    return 0;
}

/* Node tags → indices: *map[tag] (-1 = undefined), tags 0..*tmax.  0, or
 * -1 with err (sparse or repeated tags, memory). */
static int tag_map(const raw_mesh *w, const char *path, int32_t **map, long long *tmax, char *err,
                   size_t errlen)
{
    long long tmin = 0;
    *tmax = 0;
    for (size_t i = 0; i < w->nn; i++) {
        if (i == 0 || w->ntag[i] < tmin)
            tmin = w->ntag[i];
        if (i == 0 || w->ntag[i] > *tmax)
            *tmax = w->ntag[i];
    }
    if (tmin < 0 || (double)*tmax > 10.0 * (double)w->nn + 1e6) {
        snprintf(err, errlen, "%s: node tags %lld..%lld are too sparse for %zu nodes", path, tmin,
                 *tmax, w->nn);
        return -1;
    }
    *map = malloc(((size_t)*tmax + 1) * sizeof **map);
    if (!*map) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    memset(*map, 0xff, ((size_t)*tmax + 1) * sizeof **map);
    for (size_t i = 0; i < w->nn; i++) {
        if ((*map)[w->ntag[i]] >= 0) {
            snprintf(err, errlen, "%s: node tag %lld defined twice", path, w->ntag[i]);
            free(*map);
            *map = NULL;
            return -1;
        }
        (*map)[w->ntag[i]] = (int32_t)i;
    }
    return 0;
}

/* Node tags → indices; fill m. */
static int raw_to_mesh(raw_mesh *w, const char *path, pk_mesh *m, char *err, size_t errlen)
{
    if (w->nn == 0 || w->nt == 0) {
        snprintf(err, errlen, "%s: no nodes or no tetrahedra", path);
        return -1;
    }
    int32_t *map;
    long long tmax;
    if (tag_map(w, path, &map, &tmax, err, errlen))
        return -1;
    if (pk_mesh_alloc(m, w->nn, w->nt) != 0) {
        free(map);
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    memcpy(m->x, w->x, 3 * w->nn * sizeof *m->x);
    for (size_t e = 0; e < w->nt; e++) {
        for (int k = 0; k < 4; k++) {
            long long tag = w->t[4 * e + (size_t)k];
            if (tag < 0 || tag > tmax || map[tag] < 0) {
                snprintf(err, errlen, "%s: tet %zu refers to node %lld, which is not defined", path,
                         e, tag);
                free(map);
                pk_mesh_free(m);
                return -1;
            }
            m->t[4 * e + (size_t)k] = map[tag];
        }
        m->region[e] = w->region[e];
    }
    free(map);
    return 0;
}

/* Nodes per Gmsh element type (types 1–19, 92, 93). */
static int gmsh_nodes(long long type)
{
    static const int n[] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13};
    if (type >= 1 && type <= 19)
        return n[type];
    return type == 92 ? 64 : type == 93 ? 125 : -1;
}

static int msh_skip_section(reader *r, const char *name, char *err, size_t errlen)
{
    char end[140];
    snprintf(end, sizeof end, "$End%s", name + 1);
    while (next_tok(r))
        if (strcmp(r->tok, end) == 0)
            return 0;
    snprintf(err, errlen, "%s: section %s has no %s", r->path, name, end);
    return -1;
}

static int msh_element(reader *r, raw_mesh *w, long long type, int32_t region, size_t max_tets,
                       char *err, size_t errlen)
{
    int nv = gmsh_nodes(type);
    if (nv < 0) {
        snprintf(err, errlen, "%s:%ld: unknown element type %lld", r->path, r->line + 1, type);
        return -1;
    }
    long long v[4];
    for (int k = 0; k < nv; k++) {
        long long t;
        if (next_int(r, &t, err, errlen))
            return -1;
        if (k < 4)
            v[k] = t;
    }
    if (type != 4 && type != 11 && type != 29 && type != 30)
        return 0; /* not a tet (or a higher-order tet: corners first) */
    if (max_tets && w->nt >= max_tets) {
        snprintf(err, errlen, "%s: more than %zu tets, over the limit", r->path, max_tets);
        return -1;
    }
    if (raw_tet(w, v, region)) {
        snprintf(err, errlen, "%s: out of memory", r->path);
        return -1;
    }
    return 0;
}

static int msh22_nodes(reader *r, raw_mesh *w, char *err, size_t errlen)
{
    long long n, tag;
    if (next_int(r, &n, err, errlen))
        return -1;
    for (long long i = 0; i < n; i++) {
        double x[3];
        if (next_int(r, &tag, err, errlen) || next_num(r, &x[0], err, errlen) ||
            next_num(r, &x[1], err, errlen) || next_num(r, &x[2], err, errlen))
            return -1;
        if (raw_node(w, tag, x)) {
            snprintf(err, errlen, "%s: out of memory", r->path);
            return -1;
        }
    }
    return 0;
}

/* The head of a version-2.2 element record: number, type, tag count and
 * tags; *phys is the first tag (the physical group), unchanged without tags. */
static int msh22_element_head(reader *r, long long *type, long long *ntags, long long *phys,
                              char *err, size_t errlen)
{
    long long tag, t;
    if (next_int(r, &tag, err, errlen) || next_int(r, type, err, errlen) ||
        next_int(r, ntags, err, errlen))
        return -1;
    for (long long k = 0; k < *ntags; k++) {
        if (next_int(r, &t, err, errlen))
            return -1;
        if (k == 0)
            *phys = t;
    }
    return 0;
}

static int msh22_elements(reader *r, raw_mesh *w, size_t max_tets, char *err, size_t errlen)
{
    long long n, type, ntags, region = 0;
    if (next_int(r, &n, err, errlen))
        return -1;
    for (long long i = 0; i < n; i++) {
        if (msh22_element_head(r, &type, &ntags, &region, err, errlen))
            return -1;
        if (msh_element(r, w, type, (int32_t)region, max_tets, err, errlen))
            return -1;
    }
    return 0;
}

static int msh41_nodes(reader *r, raw_mesh *w, char *err, size_t errlen)
{
    long long nb, n, lo, hi;
    if (next_int(r, &nb, err, errlen) || next_int(r, &n, err, errlen) ||
        next_int(r, &lo, err, errlen) || next_int(r, &hi, err, errlen))
        return -1;
    for (long long b = 0; b < nb; b++) {
        long long dim, ent, par, cnt;
        if (next_int(r, &dim, err, errlen) || next_int(r, &ent, err, errlen) ||
            next_int(r, &par, err, errlen) || next_int(r, &cnt, err, errlen))
            return -1;
        size_t first = w->nn;
        for (long long i = 0; i < cnt; i++) {
            long long tag;
            double zero[3] = {0, 0, 0};
            if (next_int(r, &tag, err, errlen))
                return -1;
            if (raw_node(w, tag, zero)) {
                snprintf(err, errlen, "%s: out of memory", r->path);
                return -1;
            }
        }
        if (dim < 0 || dim > 3) {
            snprintf(err, errlen, "%s:%ld: entity dimension %lld", r->path, r->line + 1, dim);
            return -1;
        }
        int extra = par ? (int)dim : 0;
        for (long long i = 0; i < cnt; i++) {
            double *x = &w->x[3 * (first + (size_t)i)], u;
            for (int k = 0; k < 3; k++)
                if (next_num(r, &x[k], err, errlen))
                    return -1;
            for (int k = 0; k < extra; k++)
                if (next_num(r, &u, err, errlen))
                    return -1;
        }
    }
    return 0;
}

static int msh41_elements(reader *r, raw_mesh *w, size_t max_tets, char *err, size_t errlen)
{
    long long nb, n, lo, hi;
    if (next_int(r, &nb, err, errlen) || next_int(r, &n, err, errlen) ||
        next_int(r, &lo, err, errlen) || next_int(r, &hi, err, errlen))
        return -1;
    for (long long b = 0; b < nb; b++) {
        long long dim, ent, type, cnt, tag;
        if (next_int(r, &dim, err, errlen) || next_int(r, &ent, err, errlen) ||
            next_int(r, &type, err, errlen) || next_int(r, &cnt, err, errlen))
            return -1;
        for (long long i = 0; i < cnt; i++)
            if (next_int(r, &tag, err, errlen) ||
                msh_element(r, w, type, (int32_t)ent, max_tets, err, errlen))
                return -1;
    }
    return 0;
}

/* The $MeshFormat section: ASCII, version 2.2 or 4.1; *major = 2 or 4. */
static int msh_format(reader *r, int *major, char *err, size_t errlen)
{
    double version = 0, ftype = 0, dsize = 0;
    if (!next_tok(r) || strcmp(r->tok, "$MeshFormat") != 0) {
        snprintf(err, errlen, "%s: not a Gmsh MSH file (no $MeshFormat)", r->path);
        return -1;
    }
    if (next_num(r, &version, err, errlen) || next_num(r, &ftype, err, errlen) ||
        next_num(r, &dsize, err, errlen))
        return -1;
    if (ftype != 0) {
        snprintf(err, errlen, "%s: binary MSH is not supported (save as ASCII)", r->path);
        return -1;
    }
    if (!(version == 2.2 || (version >= 4.1 && version < 5))) {
        snprintf(err, errlen, "%s: MSH version %g is not supported (2.2 or 4.1)", r->path, version);
        return -1;
    }
    *major = (int)version; /* in range now (a forged 2e11 would not fit an int) */
    return msh_skip_section(r, "$MeshFormat", err, errlen);
}

int pk_mesh_read_msh(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen)
{
    reader r = {.path = path};
    r.f = pk_input_fopen(path, 0, err, errlen);
    if (!r.f)
        return -1;
    raw_mesh w = {0};
    int rc = -1, major = 0;
    if (msh_format(&r, &major, err, errlen))
        goto out;
    int have_nodes = 0, have_elems = 0;
    while (next_tok(&r)) {
        char name[128];
        snprintf(name, sizeof name, "%s", r.tok);
        int bad = 0;
        if (strcmp(name, "$Nodes") == 0) {
            bad = major == 2 ? msh22_nodes(&r, &w, err, errlen) : msh41_nodes(&r, &w, err, errlen);
            have_nodes = 1;
        } else if (strcmp(name, "$Elements") == 0) {
            bad = major == 2 ? msh22_elements(&r, &w, max_tets, err, errlen)
                             : msh41_elements(&r, &w, max_tets, err, errlen);
            have_elems = 1;
        } else if (name[0] != '$') {
            snprintf(err, errlen, "%s:%ld: unexpected \"%s\" between sections", path, r.line + 1,
                     name);
            goto out;
        }
        if (bad || msh_skip_section(&r, name, err, errlen))
            goto out;
    }
    if (!have_nodes || !have_elems) {
        snprintf(err, errlen, "%s: no %s section", path, have_nodes ? "$Elements" : "$Nodes");
        goto out;
    }
    rc = raw_to_mesh(&w, path, m, err, errlen);
out:
    raw_free(&w);
    fclose(r.f);
    return rc;
}

/* Attributes per TetGen node or tet: far more than any mesh carries. */
#define MAX_ATTRS 1000

/* TetGen: <base>.node ("n 3 nattr nbm", then "i x y z attrs [bm]") and
 * <base>.ele ("n 4|10 nattr", then "i n1..n4 [...] attrs"); the first index
 * sets the base (0 or 1).  The first tet attribute is the region. */
int pk_mesh_read_tetgen(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen)
{
    char base[4096], fn[4200];
    snprintf(base, sizeof base, "%s", path);
    char *dot = strrchr(base, '.');
    if (dot && (strcmp(dot, ".node") == 0 || strcmp(dot, ".ele") == 0))
        *dot = 0;
    raw_mesh w = {0};
    int rc = -1;
    reader r = {.hash_comments = 1, .path = fn};
    snprintf(fn, sizeof fn, "%s.node", base);
    r.f = pk_input_fopen(fn, 0, err, errlen);
    if (!r.f)
        return -1;
    long long n, dim, nattr, nbm, idx;
    if (next_int(&r, &n, err, errlen) || next_int(&r, &dim, err, errlen) ||
        next_int(&r, &nattr, err, errlen) || next_int(&r, &nbm, err, errlen))
        goto out;
    if (dim != 3) {
        snprintf(err, errlen, "%s: dimension %lld, expected 3", fn, dim);
        goto out;
    }
    if (nattr < 0 || nattr > MAX_ATTRS || nbm < 0 || nbm > 1) {
        snprintf(err, errlen,
                 "%s: %lld attributes and %lld boundary markers per node (at most %d "
                 "and 1)",
                 fn, nattr, nbm, MAX_ATTRS);
        goto out;
    }
    for (long long i = 0; i < n; i++) {
        double x[3], a;
        if (next_int(&r, &idx, err, errlen) || next_num(&r, &x[0], err, errlen) ||
            next_num(&r, &x[1], err, errlen) || next_num(&r, &x[2], err, errlen))
            goto out;
        for (long long k = 0; k < nattr + (nbm ? 1 : 0); k++)
            if (next_num(&r, &a, err, errlen))
                goto out;
        if (raw_node(&w, idx, x)) {
            snprintf(err, errlen, "%s: out of memory", fn);
            goto out;
        }
    }
    fclose(r.f);
    snprintf(fn, sizeof fn, "%s.ele", base);
    r.line = 0;
    r.f = pk_input_fopen(fn, 0, err, errlen);
    if (!r.f) {
        raw_free(&w);
        return -1;
    }
    long long nt, npt;
    if (next_int(&r, &nt, err, errlen) || next_int(&r, &npt, err, errlen) ||
        next_int(&r, &nattr, err, errlen))
        goto out;
    if (nattr < 0 || nattr > MAX_ATTRS) {
        snprintf(err, errlen, "%s: %lld attributes per tet (at most %d)", fn, nattr, MAX_ATTRS);
        goto out;
    }
    if (npt != 4 && npt != 10) {
        snprintf(err, errlen, "%s: %lld nodes per tet, expected 4 or 10", fn, npt);
        goto out;
    }
    if (max_tets && nt > (long long)max_tets) {
        snprintf(err, errlen, "%s: %lld tets, over the limit of %zu", fn, nt, max_tets);
        goto out;
    }
    for (long long e = 0; e < nt; e++) {
        long long v[4], t;
        double a, region = 0;
        if (next_int(&r, &idx, err, errlen))
            goto out;
        for (long long k = 0; k < npt; k++) {
            if (next_int(&r, &t, err, errlen))
                goto out;
            if (k < 4)
                v[k] = t;
        }
        for (long long k = 0; k < nattr; k++) {
            if (next_num(&r, &a, err, errlen))
                goto out;
            if (k == 0)
                region = a;
        }
        if (raw_tet(&w, v, (int32_t)lround(region))) {
            snprintf(err, errlen, "%s: out of memory", fn);
            goto out;
        }
    }
    rc = raw_to_mesh(&w, base, m, err, errlen);
out:
    raw_free(&w);
    fclose(r.f);
    return rc;
}

static int mesh_from_inline(json_t *j, pk_mesh *m, char *err, size_t errlen)
{
    json_t *nodes = json_object_get(j, "nodes"), *tets = json_object_get(j, "tets"),
           *regions = json_object_get(j, "regions");
    size_t nn = json_array_size(nodes), nt = json_array_size(tets);
    if (regions && json_array_size(regions) != nt) {
        snprintf(err, errlen, "regions: %zu entries for %zu tets", json_array_size(regions), nt);
        return -1;
    }
    if (pk_mesh_alloc(m, nn, nt) != 0) {
        snprintf(err, errlen, "out of memory for the mesh");
        return -1;
    }
    for (size_t i = 0; i < nn; i++) {
        json_t *p = json_array_get(nodes, i);
        if (json_array_size(p) != 3) {
            snprintf(err, errlen, "node %zu: needs three coordinates", i);
            pk_mesh_free(m);
            return -1;
        }
        for (size_t k = 0; k < 3; k++)
            m->x[3 * i + k] = json_number_value(json_array_get(p, k));
    }
    for (size_t e = 0; e < nt; e++) {
        json_t *t = json_array_get(tets, e);
        if (json_array_size(t) != 4) {
            snprintf(err, errlen, "tet %zu: needs four node indices", e);
            pk_mesh_free(m);
            return -1;
        }
        for (size_t k = 0; k < 4; k++) {
            long long v = -1; /* 7.0 is node 7 (pk_json_int) */
            pk_json_int(json_array_get(t, k), &v);
            m->t[4 * e + k] = v >= 0 && v < INT32_MAX ? (int32_t)v : -1;
        }
        long long reg = 0;
        if (regions)
            pk_json_int(json_array_get(regions, e), &reg);
        m->region[e] = (int32_t)reg;
    }
    return 0;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* Gmsh by name (.msh) or by content ($MeshFormat first): uploaded files
 * (the service stores them under their SHA-256) have no extension.  Looks at
 * the first 4 KiB only.  1 Gmsh, 2 a file but not Gmsh, 0 no such file (a
 * TetGen base name), -1 with err when it cannot be read (e.g. not a regular
 * file). */
static int is_gmsh(const char *file, char *err, size_t errlen)
{
    if (ends_with(file, ".msh"))
        return 1;
    FILE *f = pk_input_fopen(file, 0, err, errlen);
    if (!f)
        return errno == ENOENT ? 0 : -1;
    char head[4096];
    size_t n = fread(head, 1, sizeof head - 1, f);
    fclose(f);
    head[n] = 0;
    size_t i = 0;
    while (i < n && isspace((unsigned char)head[i]))
        i++;
    return n - i >= 11 && memcmp(head + i, "$MeshFormat", 11) == 0 ? 1 : 2;
}

int pk_mesh_from_json(json_t *j, size_t max_tets, pk_mesh *m, pk_mesh_report *rep, char *err,
                      size_t errlen)
{
    const char *file = json_string_value(json_object_get(j, "file"));
    int rc;
    if (file) {
        int gmsh = is_gmsh(file, err, errlen);
        rc = gmsh < 0   ? -1
            : gmsh == 1 ? pk_mesh_read_msh(file, max_tets, m, err, errlen)
                        : pk_mesh_read_tetgen(file, max_tets, m, err, errlen);
        if (rc != 0 && gmsh == 2 && !ends_with(file, ".node") && !ends_with(file, ".ele") &&
            !strncmp(err, "cannot open ", 12) &&
            strstr(err, ".node: ")) /* e.g. an upload that is no mesh */
            snprintf(err, errlen,
                     "%s: neither a Gmsh MSH file (no $MeshFormat at the start) nor "
                     "the base name of a TetGen .node/.ele pair",
                     file);
    } else {
        if (max_tets && json_array_size(json_object_get(j, "tets")) > max_tets) {
            snprintf(err, errlen, "the mesh has %zu tets, over the limit of %zu",
                     json_array_size(json_object_get(j, "tets")), max_tets);
            return -1;
        }
        rc = mesh_from_inline(j, m, err, errlen);
    }
    if (rc != 0)
        return -1;
    if (pk_mesh_check(m, max_tets, rep, err, errlen) != 0) {
        pk_mesh_free(m);
        return -1;
    }
    return 0;
}

/* ---- 2D meshes (pk_mesh2d): Gmsh triangles and quadrilaterals with
 * physical groups as named sets */

/* One element of dimension 0..2 as read: its corner node tags and the
 * physical groups it belongs to (2.2: its first tag; 4.1: its entity's). */
typedef struct raw2d {
    size_t n, cap;
    int8_t *dim, *nv;
    long long *v;   /* [n][4] */
    long long *ent; /* 2.2: the physical tag; 4.1: the entity tag */
} raw2d;

/* 4.1 $Entities: the physical tags of each (dim, entity). */
typedef struct ent_tab {
    size_t n, cap, nphys, pcap;
    int8_t *dim;
    long long *tag;
    size_t *first; /* [n + 1] into phys */
    long long *phys;
} ent_tab;

/* $PhysicalNames */
typedef struct phys_names {
    size_t n;
    int dim[1024];
    long long tag[1024];
    char name[1024][64];
} phys_names;

static int raw2d_add(raw2d *w, int dim, int nv, const long long v[4], long long ent)
{
    if (w->n == w->cap) {
        size_t c = w->cap ? 2 * w->cap : 256;
        int8_t *d = realloc(w->dim, c), *k = d ? realloc(w->nv, c) : NULL;
        if (d)
            w->dim = d;
        if (k)
            w->nv = k;
        long long *a = k ? realloc(w->v, 4 * c * sizeof *a) : NULL;
        if (a)
            w->v = a;
        long long *b = a ? realloc(w->ent, c * sizeof *b) : NULL;
        if (!b)
            return -1;
        w->ent = b;
        w->cap = c;
    }
    w->dim[w->n] = (int8_t)dim;
    w->nv[w->n] = (int8_t)nv;
    memcpy(&w->v[4 * w->n], v, 4 * sizeof *v);
    w->ent[w->n++] = ent;
    return 0;
}

/* One element record's nodes: keep points, lines, triangles, quads. */
static int msh2d_element(reader *r, raw2d *w, long long type, long long ent, size_t max_elems,
                         size_t *nelem, char *err, size_t errlen)
{
    int nv = gmsh_nodes(type);
    if (nv < 0) {
        snprintf(err, errlen, "%s:%ld: unknown element type %lld", r->path, r->line + 1, type);
        return -1;
    }
    long long v[4] = {-1, -1, -1, -1};
    for (int k = 0; k < nv; k++) {
        long long t;
        if (next_int(r, &t, err, errlen))
            return -1;
        if (k < 4)
            v[k] = t;
    }
    int dim = type == 15 ? 0 : type == 1 ? 1 : type == 2 || type == 3 ? 2 : -1;
    if (dim < 0) {
        snprintf(err, errlen,
                 "%s:%ld: element type %lld: a 2D mesh takes 3-node triangles (2) and "
                 "4-node quadrilaterals (3), with points (15) and lines (1) for groups",
                 r->path, r->line + 1, type);
        return -1;
    }
    if (dim == 2 && max_elems && ++*nelem > max_elems) {
        snprintf(err, errlen, "%s: more than %zu elements, over the limit", r->path, max_elems);
        return -1;
    }
    if (raw2d_add(w, dim, nv, v, ent)) {
        snprintf(err, errlen, "%s: out of memory", r->path);
        return -1;
    }
    return 0;
}

static int msh2d_names(reader *r, phys_names *pn, char *err, size_t errlen)
{
    long long n, dim, tag;
    if (next_int(r, &n, err, errlen))
        return -1;
    for (long long i = 0; i < n; i++) {
        if (next_int(r, &dim, err, errlen) || next_int(r, &tag, err, errlen) || !next_tok(r)) {
            if (!err[0])
                snprintf(err, errlen, "%s:%ld: a physical name is missing", r->path, r->line + 1);
            return -1;
        }
        char name[256];
        snprintf(name, sizeof name, "%s", r->tok);
        while (strlen(name) > 0 && (strlen(name) < 2 || name[strlen(name) - 1] != '"')) {
            if (!next_tok(r)) { /* a quoted name with spaces */
                snprintf(err, errlen, "%s: unterminated physical name", r->path);
                return -1;
            }
            size_t l = strlen(name);
            snprintf(name + l, sizeof name - l, " %s", r->tok);
        }
        size_t l = strlen(name);
        if (pn->n < sizeof pn->dim / sizeof *pn->dim) {
            pn->dim[pn->n] = (int)dim;
            pn->tag[pn->n] = tag;
            snprintf(pn->name[pn->n], sizeof pn->name[0], "%.*s", (int)(l >= 2 ? l - 2 : 0),
                     name + 1);
            pn->n++;
        }
    }
    return 0;
}

/* 4.1 $Entities: points "tag x y z nphys phys...", curves and surfaces
 * "tag box(6) nphys phys... nbound bound...", volumes skipped alike. */
static int msh41_entities(reader *r, ent_tab *t, char *err, size_t errlen)
{
    long long cnt[4];
    for (int d = 0; d < 4; d++)
        if (next_int(r, &cnt[d], err, errlen))
            return -1;
    for (int d = 0; d < 4; d++)
        for (long long i = 0; i < cnt[d]; i++) {
            long long tag, np, nb, x;
            double box;
            if (next_int(r, &tag, err, errlen))
                return -1;
            for (int k = 0; k < (d == 0 ? 3 : 6); k++)
                if (next_num(r, &box, err, errlen))
                    return -1;
            if (next_int(r, &np, err, errlen))
                return -1;
            if (np < 0 || np > 1000000) {
                snprintf(err, errlen, "%s:%ld: %lld physical tags", r->path, r->line + 1, np);
                return -1;
            }
            size_t first = t->nphys;
            for (long long k = 0; k < np; k++) {
                if (next_int(r, &x, err, errlen))
                    return -1;
                if (t->nphys == t->pcap) {
                    size_t c = t->pcap ? 2 * t->pcap : 64;
                    long long *p = realloc(t->phys, c * sizeof *p);
                    if (!p)
                        goto oom;
                    t->phys = p;
                    t->pcap = c;
                }
                t->phys[t->nphys++] = x < 0 ? -x : x;
            }
            if (d > 0) {
                if (next_int(r, &nb, err, errlen))
                    return -1;
                for (long long k = 0; k < nb; k++)
                    if (next_int(r, &x, err, errlen))
                        return -1;
            }
            if (t->n + 2 > t->cap) {
                size_t c = t->cap ? 2 * t->cap : 64;
                int8_t *dd = realloc(t->dim, c * sizeof *dd);
                if (dd)
                    t->dim = dd;
                long long *tt = dd ? realloc(t->tag, c * sizeof *tt) : NULL;
                if (tt)
                    t->tag = tt;
                size_t *ff = tt ? realloc(t->first, c * sizeof *ff) : NULL;
                if (!ff)
                    goto oom;
                t->first = ff;
                t->cap = c;
            }
            t->dim[t->n] = (int8_t)d;
            t->tag[t->n] = tag;
            t->first[t->n] = first;
            t->first[++t->n] = t->nphys;
        }
    return 0;
oom:
    snprintf(err, errlen, "%s: out of memory", r->path);
    return -1;
}

static int msh2d_elements(reader *r, int major, raw2d *w, size_t max_elems, char *err,
                          size_t errlen)
{
    size_t nelem = 0;
    long long n, tag, type, ntags, ent = 0;
    if (major == 2) {
        if (next_int(r, &n, err, errlen))
            return -1;
        for (long long i = 0; i < n; i++) {
            if (msh22_element_head(r, &type, &ntags, &ent, err, errlen))
                return -1;
            if (msh2d_element(r, w, type, ntags ? ent : 0, max_elems, &nelem, err, errlen))
                return -1;
        }
        return 0;
    }
    long long nb, lo, hi;
    if (next_int(r, &nb, err, errlen) || next_int(r, &n, err, errlen) ||
        next_int(r, &lo, err, errlen) || next_int(r, &hi, err, errlen))
        return -1;
    for (long long b = 0; b < nb; b++) {
        long long dim, cnt;
        if (next_int(r, &dim, err, errlen) || next_int(r, &ent, err, errlen) ||
            next_int(r, &type, err, errlen) || next_int(r, &cnt, err, errlen))
            return -1;
        for (long long i = 0; i < cnt; i++)
            if (next_int(r, &tag, err, errlen) ||
                msh2d_element(r, w, type, ent, max_elems, &nelem, err, errlen))
                return -1;
    }
    return 0;
}

pk_mesh2d_set *pk_mesh2d_add_set(pk_mesh2d *m, const char *name)
{
    pk_mesh2d_set *s = realloc(m->set, (m->nset + 1) * sizeof *s);
    if (!s)
        return NULL;
    m->set = s;
    s = &m->set[m->nset++];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name);
    return s;
}

const pk_mesh2d_set *pk_mesh2d_find(const pk_mesh2d *m, const char *name)
{
    for (size_t i = 0; name && i < m->nset; i++)
        if (!strcmp(m->set[i].name, name))
            return &m->set[i];
    return NULL;
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

void pk_mesh2d_set_finish(pk_mesh2d_set *s)
{
    if (!s->nnode)
        return;
    qsort(s->node, s->nnode, sizeof *s->node, cmp_i32);
    size_t k = 1;
    for (size_t i = 1; i < s->nnode; i++)
        if (s->node[i] != s->node[k - 1])
            s->node[k++] = s->node[i];
    s->nnode = k;
}

void pk_mesh2d_free(pk_mesh2d *m)
{
    for (size_t i = 0; i < m->nset; i++) {
        free(m->set[i].node);
        free(m->set[i].edge);
        free(m->set[i].elem);
    }
    free(m->set);
    free(m->xy);
    free(m->conn);
    memset(m, 0, sizeof *m);
}

/* Add element k of w (nodes mapped, e its index among the 2D elements) to
 * the set of group (dim, phys), made on first use. */
static int add_to_group(pk_mesh2d *m, const phys_names *pn, int dim, long long phys,
                        const int32_t *v, int nv, size_t e)
{
    char name[64];
    snprintf(name, sizeof name, "%d:%lld", dim, phys);
    for (size_t i = 0; i < pn->n; i++)
        if (pn->dim[i] == dim && pn->tag[i] == phys && pn->name[i][0])
            snprintf(name, sizeof name, "%s", pn->name[i]);
    pk_mesh2d_set *s = (pk_mesh2d_set *)pk_mesh2d_find(m, name);
    if (!s && !(s = pk_mesh2d_add_set(m, name)))
        return -1;
    int32_t *nodes = realloc(s->node, (s->nnode + (size_t)nv) * sizeof *nodes);
    if (!nodes)
        return -1;
    s->node = nodes;
    for (int k = 0; k < nv; k++)
        s->node[s->nnode++] = v[k];
    if (dim == 1) {
        int32_t *ed = realloc(s->edge, 2 * (s->nedge + 1) * sizeof *ed);
        if (!ed)
            return -1;
        s->edge = ed;
        s->edge[2 * s->nedge] = v[0];
        s->edge[2 * s->nedge++ + 1] = v[1];
    }
    if (dim == 2) {
        int32_t *el = realloc(s->elem, (s->nelem + 1) * sizeof *el);
        if (!el)
            return -1;
        s->elem = el;
        s->elem[s->nelem++] = (int32_t)e;
    }
    return 0;
}

static int raw2d_to_mesh(const raw_mesh *nodes, const raw2d *w, const ent_tab *et,
                         const phys_names *pn, int major, const char *path, pk_mesh2d *m, char *err,
                         size_t errlen)
{
    size_t ne = 0;
    for (size_t k = 0; k < w->n; k++)
        ne += w->dim[k] == 2;
    if (nodes->nn == 0 || ne == 0) {
        snprintf(err, errlen, "%s: no nodes or no triangles/quadrilaterals", path);
        return -1;
    }
    int32_t *map;
    long long tmax;
    if (tag_map(nodes, path, &map, &tmax, err, errlen))
        return -1;
    memset(m, 0, sizeof *m);
    m->nnode = nodes->nn;
    m->nelem = ne;
    m->xy = malloc(2 * nodes->nn * sizeof *m->xy);
    m->conn = malloc(4 * ne * sizeof *m->conn);
    if (!m->xy || !m->conn)
        goto oom;
    for (size_t i = 0; i < nodes->nn; i++) {
        m->xy[2 * i] = nodes->x[3 * i];
        m->xy[2 * i + 1] = nodes->x[3 * i + 1];
    }
    for (size_t k = 0, e = 0; k < w->n; k++) {
        int32_t v[4] = {-1, -1, -1, -1};
        int nv = w->nv[k];
        for (int j = 0; j < nv; j++) {
            long long tag = w->v[4 * k + (size_t)j];
            if (tag < 0 || tag > tmax || map[tag] < 0) {
                snprintf(err, errlen, "%s: an element refers to node %lld, which is not defined",
                         path, tag);
                goto fail;
            }
            v[j] = map[tag];
        }
        if (w->dim[k] == 2)
            memcpy(&m->conn[4 * e], v, sizeof v);
        if (major == 2) {
            if (w->ent[k] > 0 && add_to_group(m, pn, w->dim[k], w->ent[k], v, nv, e))
                goto oom;
        } else
            for (size_t t = 0; t < et->n; t++)
                if (et->dim[t] == w->dim[k] && et->tag[t] == w->ent[k])
                    for (size_t p = et->first[t]; p < et->first[t + 1]; p++)
                        if (add_to_group(m, pn, w->dim[k], et->phys[p], v, nv, e))
                            goto oom;
        e += w->dim[k] == 2;
    }
    for (size_t i = 0; i < m->nset; i++)
        pk_mesh2d_set_finish(&m->set[i]);
    free(map);
    return 0;
oom:
    snprintf(err, errlen, "%s: out of memory", path);
fail:
    free(map);
    pk_mesh2d_free(m);
    return -1;
}

int pk_mesh2d_read_msh(const char *path, size_t max_elems, pk_mesh2d *m, char *err, size_t errlen)
{
    memset(m, 0, sizeof *m);
    reader r = {.path = path};
    r.f = pk_input_fopen(path, 0, err, errlen);
    if (!r.f)
        return -1;
    raw_mesh nodes = {0};
    raw2d w = {0};
    ent_tab et = {0};
    phys_names *pn = calloc(1, sizeof *pn);
    int rc = -1, major = 0;
    if (!pn) {
        snprintf(err, errlen, "%s: out of memory", path);
        goto out;
    }
    if (msh_format(&r, &major, err, errlen))
        goto out;
    int have_nodes = 0, have_elems = 0;
    while (next_tok(&r)) {
        char name[128];
        snprintf(name, sizeof name, "%s", r.tok);
        int bad = 0;
        err[0] = 0;
        if (strcmp(name, "$Nodes") == 0) {
            bad = major == 2 ? msh22_nodes(&r, &nodes, err, errlen)
                             : msh41_nodes(&r, &nodes, err, errlen);
            have_nodes = 1;
        } else if (strcmp(name, "$Elements") == 0) {
            bad = msh2d_elements(&r, major, &w, max_elems, err, errlen);
            have_elems = 1;
        } else if (strcmp(name, "$PhysicalNames") == 0)
            bad = msh2d_names(&r, pn, err, errlen);
        else if (strcmp(name, "$Entities") == 0 && major == 4)
            bad = msh41_entities(&r, &et, err, errlen);
        else if (name[0] != '$') {
            snprintf(err, errlen, "%s:%ld: unexpected \"%s\" between sections", path, r.line + 1,
                     name);
            goto out;
        }
        if (bad || msh_skip_section(&r, name, err, errlen))
            goto out;
    }
    if (!have_nodes || !have_elems) {
        snprintf(err, errlen, "%s: no %s section", path, have_nodes ? "$Elements" : "$Nodes");
        goto out;
    }
    rc = raw2d_to_mesh(&nodes, &w, &et, pn, major, path, m, err, errlen);
out:
    raw_free(&nodes);
    free(w.dim);
    free(w.nv);
    free(w.v);
    free(w.ent);
    free(et.dim);
    free(et.tag);
    free(et.first);
    free(et.phys);
    free(pn);
    fclose(r.f);
    return rc;
}
