/* mesh.c — a linear tet mesh: allocation, checks (orientation, conformity,
 * manifold boundary), boundary faces, volumes.  Contract: core/mesh/mesh.h. */
#include "mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_edges.h"

/* Outward faces of a positively oriented tet (v0..v3), the face opposite
 * local node k is kFace[k] (right-hand normal points away from node k). */
static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

int pk_mesh_alloc(pk_mesh *m, size_t nnode, size_t ntet)
{
    memset(m, 0, sizeof *m);
    m->nnode = nnode;
    m->ntet = ntet;
    m->x = malloc((nnode ? nnode : 1) * 3 * sizeof *m->x);
    m->t = malloc((ntet ? ntet : 1) * 4 * sizeof *m->t);
    m->region = calloc(ntet ? ntet : 1, sizeof *m->region);
    if (!m->x || !m->t || !m->region) {
        pk_mesh_free(m);
        return -1;
    }
    return 0;
}

void pk_mesh_free(pk_mesh *m)
{
    free(m->x);
    free(m->t);
    free(m->region);
    free(m->bface);
    free(m->bface_tet);
    memset(m, 0, sizeof *m);
}

void pk_mesh_translate(pk_mesh *m, const double off[3])
{
    for (size_t i = 0; i < m->nnode; i++)
        for (int k = 0; k < 3; k++)
            m->x[3 * i + k] -= off[k];
    for (int k = 0; k < 3; k++) {
        m->lo[k] -= off[k];
        m->hi[k] -= off[k];
    }
}

static double det3(const double *a, const double *b, const double *c)
{
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
        a[2] * (b[0] * c[1] - b[1] * c[0]);
}

double pk_mesh_tet_volume(const pk_mesh *m, size_t e)
{
    const int32_t *t = &m->t[4 * e];
    const double *p0 = &m->x[3 * (size_t)t[0]];
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; k++) {
        a[k] = m->x[3 * (size_t)t[1] + k] - p0[k];
        b[k] = m->x[3 * (size_t)t[2] + k] - p0[k];
        c[k] = m->x[3 * (size_t)t[3] + k] - p0[k];
    }
    return det3(a, b, c) / 6;
}

/* Edge lengths of tet e: max and root-mean-square. */
static void tet_edges(const pk_mesh *m, size_t e, double *lmax, double *lrms)
{
    const int32_t *t = &m->t[4 * e];
    double mx = 0, s = 0;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) {
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                double d = m->x[3 * (size_t)t[i] + k] - m->x[3 * (size_t)t[j] + k];
                d2 += d * d;
            }
            mx = fmax(mx, d2);
            s += d2;
        }
    *lmax = sqrt(mx);
    *lrms = sqrt(s / 6);
}

/* Pass 1: indices in range, orientation, zero volume, slivers, volume, bbox. */
static int check_tets(pk_mesh *m, pk_mesh_report *rep, char *err, size_t errlen)
{
    m->volume = 0;
    for (int k = 0; k < 3; k++) {
        m->lo[k] = INFINITY;
        m->hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < m->nnode; i++)
        for (int k = 0; k < 3; k++) {
            double v = m->x[3 * i + k];
            if (!isfinite(v)) {
                snprintf(err, errlen, "node %zu has a non-finite coordinate", i);
                return -1;
            }
            m->lo[k] = fmin(m->lo[k], v);
            m->hi[k] = fmax(m->hi[k], v);
        }
    for (size_t e = 0; e < m->ntet; e++) {
        int32_t *t = &m->t[4 * e];
        for (int i = 0; i < 4; i++) {
            if (t[i] < 0 || (size_t)t[i] >= m->nnode) {
                snprintf(err, errlen, "tet %zu refers to node %d, but the mesh has %zu nodes", e,
                         (int)t[i], m->nnode);
                return -1;
            }
            for (int j = 0; j < i; j++)
                if (t[i] == t[j]) {
                    snprintf(err, errlen, "tet %zu uses node %d twice (zero volume)", e, (int)t[i]);
                    return -1;
                }
        }
        double v = pk_mesh_tet_volume(m, e), lmax, lrms;
        tet_edges(m, e, &lmax, &lrms);
        if (!(fabs(v) > PK_MESH_ZERO_VOLUME * lmax * lmax * lmax)) {
            snprintf(err, errlen, "tet %zu has zero volume (|V| = %.3g, longest edge %.3g)", e,
                     fabs(v), lmax);
            return -1;
        }
        if (v < 0) { /* inverted: swap two nodes */
            int32_t s = t[2];
            t[2] = t[3];
            t[3] = s;
            v = -v;
            rep->reoriented++;
        }
        double q = 6 * sqrt(2.0) * v / (lrms * lrms * lrms);
        if (q < rep->min_quality)
            rep->min_quality = q;
        if (q < PK_MESH_SLIVER_QUALITY) {
            if (rep->slivers++ == 0)
                rep->first_sliver = e;
        }
        m->volume += v;
    }
    return 0;
}

/* Scratch records for the face and edge passes: at least one element so an
 * empty mesh still gets a valid pointer; the error names what was counted. */
static void *alloc_records(size_t n, size_t size, const char *what, char *err, size_t errlen)
{
    void *p = malloc((n ? n : 1) * size);
    if (!p)
        snprintf(err, errlen, "out of memory for %zu %s", n, what);
    return p;
}

typedef struct face_rec {
    int32_t key[3]; /* sorted node indices */
    int32_t tet;
    int8_t local;  /* opposite local node */
    int8_t parity; /* orientation of the outward face relative to the sorted key */
} face_rec;

static int cmp_face(const void *a, const void *b)
{
    const face_rec *f = a, *g = b;
    for (int k = 0; k < 3; k++)
        if (f->key[k] != g->key[k])
            return f->key[k] < g->key[k] ? -1 : 1;
    return 0;
}

/* Sort three values; return the permutation parity (0 even, 1 odd). */
static int sort3(int32_t v[3])
{
    int par = 0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 - i; j++)
            if (v[j] > v[j + 1]) {
                int32_t s = v[j];
                v[j] = v[j + 1];
                v[j + 1] = s;
                par ^= 1;
            }
    return par;
}

/* Pass 2: faces.  A face in one tet is a boundary face, in two tets it must be
 * seen with opposite orientations (else the tets overlap), in more the mesh
 * is non-manifold. */
static int build_faces(pk_mesh *m, char *err, size_t errlen)
{
    size_t nf = 4 * m->ntet;
    face_rec *f = alloc_records(nf, sizeof *f, "faces", err, errlen);
    if (!f)
        return -1;
    for (size_t e = 0; e < m->ntet; e++)
        for (int k = 0; k < 4; k++) {
            face_rec *r = &f[4 * e + (size_t)k];
            for (int j = 0; j < 3; j++)
                r->key[j] = m->t[4 * e + (size_t)kFace[k][j]];
            r->parity = (int8_t)sort3(r->key);
            r->tet = (int32_t)e;
            r->local = (int8_t)k;
        }
    qsort(f, nf, sizeof *f, cmp_face);
    size_t nb = 0;
    for (size_t i = 0; i < nf;) {
        size_t j = i + 1;
        while (j < nf && cmp_face(&f[i], &f[j]) == 0)
            j++;
        if (j - i == 1)
            nb++;
        else if (j - i == 2 && f[i].parity == f[i + 1].parity) {
            snprintf(err, errlen,
                     "tets %d and %d overlap: both lie on the same side of face "
                     "(%d, %d, %d)",
                     (int)f[i].tet, (int)f[i + 1].tet, (int)f[i].key[0], (int)f[i].key[1],
                     (int)f[i].key[2]);
            free(f);
            return -1;
        } else if (j - i > 2) {
            snprintf(err, errlen,
                     "non-manifold mesh: face (%d, %d, %d) is shared by %zu tets "
                     "(tets %d, %d, %d, ...)",
                     (int)f[i].key[0], (int)f[i].key[1], (int)f[i].key[2], j - i, (int)f[i].tet,
                     (int)f[i + 1].tet, (int)f[i + 2].tet);
            free(f);
            return -1;
        }
        i = j;
    }
    m->nbface = nb;
    m->bface = malloc((nb ? nb : 1) * 3 * sizeof *m->bface);
    m->bface_tet = malloc((nb ? nb : 1) * sizeof *m->bface_tet);
    if (!m->bface || !m->bface_tet) {
        free(f);
        snprintf(err, errlen, "out of memory for %zu boundary faces", nb);
        return -1;
    }
    nb = 0;
    for (size_t i = 0; i < nf;) {
        size_t j = i + 1;
        while (j < nf && cmp_face(&f[i], &f[j]) == 0)
            j++;
        if (j - i == 1) {
            size_t e = (size_t)f[i].tet;
            for (int k = 0; k < 3; k++)
                m->bface[3 * nb + (size_t)k] = m->t[4 * e + (size_t)kFace[f[i].local][k]];
            m->bface_tet[nb++] = f[i].tet;
        }
        i = j;
    }
    free(f);
    return 0;
}

int pk_mesh_faces(const pk_mesh *m, int32_t **faces, size_t *nface)
{
    size_t nf = 4 * m->ntet;
    face_rec *f = malloc((nf ? nf : 1) * sizeof *f);
    *faces = NULL;
    *nface = 0;
    if (!f)
        return -1;
    for (size_t e = 0; e < m->ntet; e++)
        for (int k = 0; k < 4; k++) {
            face_rec *r = &f[4 * e + (size_t)k];
            for (int j = 0; j < 3; j++)
                r->key[j] = m->t[4 * e + (size_t)kFace[k][j]];
            sort3(r->key);
        }
    qsort(f, nf, sizeof *f, cmp_face);
    size_t u = 0;
    for (size_t i = 0; i < nf; i++)
        if (u == 0 || cmp_face(&f[i], &f[u - 1]) != 0)
            f[u++] = f[i];
    int32_t *out = malloc((u ? u : 1) * 3 * sizeof *out);
    if (!out) {
        free(f);
        return -1;
    }
    for (size_t i = 0; i < u; i++)
        memcpy(&out[3 * i], f[i].key, sizeof f[i].key);
    free(f);
    *faces = out;
    *nface = u;
    return 0;
}

typedef struct edge_rec {
    uint64_t key; /* (min << 32) | max */
    int32_t face;
    int8_t dir; /* +1 if the face runs min → max */
} edge_rec;

static int cmp_edge(const void *a, const void *b)
{
    const edge_rec *e = a, *g = b;
    return e->key < g->key ? -1 : e->key > g->key;
}

/* Pass 3: the boundary is a closed 2-manifold: every boundary edge is shared
 * by exactly two boundary faces running it in opposite directions.  An edge
 * seen once is a hanging (non-conforming) face or a hole; seen more often, a
 * non-manifold edge. */
static int check_boundary(const pk_mesh *m, char *err, size_t errlen)
{
    size_t ne = 3 * m->nbface;
    edge_rec *r = alloc_records(ne, sizeof *r, "boundary edges", err, errlen);
    if (!r)
        return -1;
    for (size_t f = 0; f < m->nbface; f++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = (uint32_t)m->bface[3 * f + (size_t)k];
            uint32_t b = (uint32_t)m->bface[3 * f + (size_t)(k + 1) % 3];
            edge_rec *e = &r[3 * f + (size_t)k];
            e->dir = a < b ? 1 : -1;
            e->key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            e->face = (int32_t)f;
        }
    qsort(r, ne, sizeof *r, cmp_edge);
    int rc = 0;
    for (size_t i = 0; i < ne && rc == 0;) {
        size_t j = i + 1;
        while (j < ne && r[j].key == r[i].key)
            j++;
        int a = (int)(r[i].key >> 32), b = (int)(r[i].key & 0xffffffffu);
        int32_t f = r[i].face;
        if (j - i == 1) {
            snprintf(err, errlen,
                     "non-conforming mesh or open boundary: edge (%d, %d) of boundary "
                     "face (%d, %d, %d) of tet %d has no matching face",
                     a, b, (int)m->bface[3 * (size_t)f], (int)m->bface[3 * (size_t)f + 1],
                     (int)m->bface[3 * (size_t)f + 2], (int)m->bface_tet[f]);
            rc = -1;
        } else if (j - i > 2 || r[i].dir == r[i + 1].dir) {
            snprintf(
                err, errlen,
                "non-manifold or non-conforming boundary: edge (%d, %d) is shared by %zu boundary "
                "faces (tets %d and %d)",
                a, b, j - i, (int)m->bface_tet[r[i].face], (int)m->bface_tet[r[i + 1].face]);
            rc = -1;
        }
        i = j;
    }
    free(r);
    return rc;
}

int pk_mesh_check(pk_mesh *m, size_t max_tets, pk_mesh_report *rep, char *err, size_t errlen)
{
    pk_mesh_report local;
    if (!rep)
        rep = &local;
    *rep = (pk_mesh_report){.first_sliver = SIZE_MAX, .min_quality = INFINITY};
    if (m->ntet == 0 || m->nnode < 4) {
        snprintf(err, errlen, "the mesh has no tets (%zu nodes, %zu tets)", m->nnode, m->ntet);
        return -1;
    }
    if (max_tets && m->ntet > max_tets) {
        snprintf(err, errlen, "the mesh has %zu tets, over the limit of %zu", m->ntet, max_tets);
        return -1;
    }
    if (m->nnode > (size_t)INT32_MAX || m->ntet > (size_t)INT32_MAX / 4) {
        snprintf(err, errlen, "the mesh is too large for 32-bit indices");
        return -1;
    }
    free(m->bface);
    free(m->bface_tet);
    m->bface = NULL;
    m->bface_tet = NULL;
    if (check_tets(m, rep, err, errlen) || build_faces(m, err, errlen) ||
        check_boundary(m, err, errlen))
        return -1;
    pk_mesh_edge_list el;
    if (pk_mesh_edges(m, &el) != 0) {
        snprintf(err, errlen, "out of memory for the edge list");
        return -1;
    }
    double s = 0;
    for (size_t i = 0; i < el.n; i++)
        s += pk_mesh_edge_length(m, &el, i);
    m->edge_mean = el.n ? s / (double)el.n : 0;
    pk_mesh_edges_free(&el);
    return 0;
}
