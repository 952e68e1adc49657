/* edmd_contacts.c — contacts, rattlers and mean contact number at the end.
 * Contract: core/edmd/edmd_contacts.h. */
#include "edmd_contacts.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/space/grid.h"

double pk_contact_tolerance(int dim, double p)
{
    if (!(p > 0))
        return 1e-3;
    return fmin(fmax(1e3 * dim / p, 1e-12), 1e-3);
}

typedef struct cctx {
    const pk_particles *p;
    size_t self;
    double delta_d, tol;
    int32_t *pi, *pj;
    size_t n, cap;
    int failed;
} cctx;

static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    cctx *c = ctx;
    if (j <= c->self)
        return 0;
    double R = c->p->r[c->self] + c->p->r[j];
    if (sqrt(dist2) - R > c->delta_d + c->tol * R)
        return 0;
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 1024;
        int32_t *a = realloc(c->pi, cap * sizeof *a);
        if (!a) {
            c->failed = 1;
            return 1;
        }
        c->pi = a;
        int32_t *b = realloc(c->pj, cap * sizeof *b);
        if (!b) {
            c->failed = 1;
            return 1;
        }
        c->pj = b;
        c->cap = cap;
    }
    c->pi[c->n] = (int32_t)c->self;
    c->pj[c->n] = (int32_t)j;
    c->n++;
    return 0;
}

int pk_contact_stats_compute(const pk_box *b, const pk_particles *p, double delta_d, double tol,
                             pk_contact_stats *cs)
{
    *cs = (pk_contact_stats){0};
    if (p->n == 0)
        return 0;
    double rmin = INFINITY, rmax = 0;
    for (size_t i = 0; i < p->n; i++) {
        rmin = fmin(rmin, p->r[i]);
        rmax = fmax(rmax, p->r[i]);
    }
    if (!(rmax > 0))
        return 0;
    pk_grid g;
    double extra = delta_d + 2 * tol * rmax;
    if (pk_grid_init(&g, b, rmin, rmax, extra, p->n) != 0)
        return -1;
    cctx c = {.p = p, .delta_d = delta_d, .tol = tol};
    int rc = -1;
    int32_t *deg = calloc(p->n, sizeof *deg);
    uint8_t *gone = calloc(p->n, 1);
    size_t *off = NULL;
    int32_t *adj = NULL, *stack = NULL;
    if (!deg || !gone)
        goto out;
    for (size_t i = 0; i < p->n; i++)
        if (pk_grid_insert(&g, p, i) != 0)
            goto out;
    for (size_t i = 0; i < p->n && !c.failed; i++) {
        c.self = i;
        pk_grid_query(&g, p, &p->x[3 * i], p->r[i], 0.0, visit, &c);
    }
    if (c.failed)
        goto out;
    for (size_t k = 0; k < c.n; k++) {
        deg[c.pi[k]]++;
        deg[c.pj[k]]++;
    }
    /* adjacency (CSR), then peel: a grain with fewer than dim+1 contacts to
     * the remaining grains cannot be locally jammed */
    off = calloc(p->n + 1, sizeof *off);
    adj = malloc((2 * c.n + 1) * sizeof *adj);
    stack = malloc(p->n * sizeof *stack);
    if (!off || !adj || !stack)
        goto out;
    for (size_t i = 0; i < p->n; i++)
        off[i + 1] = off[i] + (size_t)deg[i];
    for (size_t k = 0; k < c.n; k++) {
        adj[off[c.pi[k]]++] = c.pj[k];
        adj[off[c.pj[k]]++] = c.pi[k];
    }
    for (size_t i = p->n; i > 0; i--)
        off[i] = off[i - 1];
    off[0] = 0;
    size_t top = 0;
    for (size_t i = 0; i < p->n; i++)
        if (deg[i] < p->dim + 1) {
            gone[i] = 1;
            stack[top++] = (int32_t)i;
        }
    while (top) {
        size_t i = (size_t)stack[--top];
        cs->rattlers++;
        for (size_t q = off[i]; q < off[i + 1]; q++) {
            size_t j = (size_t)adj[q];
            if (gone[j])
                continue;
            if (--deg[j] < p->dim + 1) {
                gone[j] = 1;
                stack[top++] = (int32_t)j;
            }
        }
    }
    cs->contacts = c.n;
    cs->rattler_fraction = (double)cs->rattlers / (double)p->n;
    size_t backbone = p->n - cs->rattlers;
    if (backbone) {
        double z = 0;
        for (size_t i = 0; i < p->n; i++)
            if (!gone[i])
                z += deg[i];
        cs->mean_contacts = z / (double)backbone;
    }
    rc = 0;
out:
    free(deg);
    free(gone);
    free(off);
    free(adj);
    free(stack);
    free(c.pi);
    free(c.pj);
    pk_grid_free(&g);
    return rc;
}
