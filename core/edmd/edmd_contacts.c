/* edmd_contacts.c — contacts, rattlers and mean contact number at the end.
 * Contract: core/edmd/edmd_contacts.h. */
#include "edmd_contacts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    pk_contact_network net;
    size_t cap;
    int failed;
} cctx;

static int grow_pairs(cctx *c)
{
    size_t cap = c->cap ? 2 * c->cap : 1024;
    int32_t *a = realloc(c->net.pi, cap * sizeof *a);
    if (!a)
        return -1;
    c->net.pi = a;
    int32_t *b = realloc(c->net.pj, cap * sizeof *b);
    if (!b)
        return -1;
    c->net.pj = b;
    double *nr = realloc(c->net.normal, 3 * cap * sizeof *nr);
    if (!nr)
        return -1;
    c->net.normal = nr;
    c->cap = cap;
    return 0;
}

static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    cctx *c = ctx;
    if (j <= c->self)
        return 0;
    double R = c->p->r[c->self] + c->p->r[j], dist = sqrt(dist2);
    if (dist - R > c->delta_d + c->tol * R)
        return 0;
    if (c->net.npair == c->cap && grow_pairs(c) != 0) {
        c->failed = 1;
        return 1;
    }
    size_t k = c->net.npair++;
    c->net.pi[k] = (int32_t)c->self;
    c->net.pj[k] = (int32_t)j;
    for (int a = 0; a < 3; a++)
        c->net.normal[3 * k + a] = a < c->p->dim && dist > 0 ? dx[a] / dist : 0;
    return 0;
}

/* Wall contacts: clearance to a wall of a walled axis ≤ wall_gap + tol·2r. */
static int wall_contacts(const pk_box *b, const pk_particles *p, double wall_gap, double tol,
                         pk_contact_network *net)
{
    size_t cap = 0;
    for (size_t i = 0; i < p->n; i++)
        for (int k = 0; k < b->dim; k++) {
            if (b->periodic[k])
                continue;
            const double x = p->x[3 * i + k], r = p->r[i], reach = wall_gap + tol * 2 * r;
            const int lo = x - r <= reach, hi = b->L[k] - x - r <= reach;
            for (int s = 0; s < lo + hi; s++) {
                if (net->nwall == cap) {
                    cap = cap ? 2 * cap : 256;
                    int32_t *w = realloc(net->wi, cap * sizeof *w);
                    if (!w)
                        return -1;
                    net->wi = w;
                    int8_t *a = realloc(net->waxis, cap);
                    if (!a)
                        return -1;
                    net->waxis = a;
                }
                net->wi[net->nwall] = (int32_t)i;
                net->waxis[net->nwall++] = (int8_t)k;
            }
        }
    return 0;
}

void pk_contact_network_free(pk_contact_network *net)
{
    free(net->pi);
    free(net->pj);
    free(net->normal);
    free(net->wi);
    free(net->waxis);
    free(net->rattler);
    memset(net, 0, sizeof *net);
}

/* The contact graph as CSR: grain i's neighbours adj[off[i] .. off[i+1]-1],
 * -1 for a wall.  deg[i] is grain i's contact count.  -1 when out of memory
 * (*off, *adj set to what must be freed). */
static int build_adjacency(const pk_contact_network *net, size_t n, const int32_t *deg,
                           size_t **off_out, int32_t **adj_out)
{
    size_t *off = malloc((n + 1) * sizeof *off);
    *off_out = off;
    *adj_out = NULL;
    if (!off)
        return -1;
    off[0] = 0;
    for (size_t i = 0; i < n; i++)
        off[i + 1] = off[i] + (size_t)deg[i];
    int32_t *adj = malloc((off[n] + 1) * sizeof *adj);
    *adj_out = adj;
    size_t *fill = malloc((n + 1) * sizeof *fill);
    if (!adj || !fill) {
        free(fill);
        return -1;
    }
    memcpy(fill, off, (n + 1) * sizeof *fill);
    for (size_t k = 0; k < net->npair; k++) {
        adj[fill[net->pi[k]]++] = net->pj[k];
        adj[fill[net->pj[k]]++] = net->pi[k];
    }
    for (size_t k = 0; k < net->nwall; k++)
        adj[fill[net->wi[k]]++] = -1; /* a wall: never peeled */
    free(fill);
    return 0;
}

/* Peel: a grain with fewer than dim+1 contacts to the remaining grains and
 * the walls cannot be locally jammed; removing it may leave a neighbour
 * short too.  Sets gone[i] for the rattlers, lowers deg to the contacts
 * within the backbone, and returns the rattler count.  stack: n entries. */
static size_t peel_rattlers(size_t n, int dim, const size_t *off, const int32_t *adj, int32_t *deg,
                            uint8_t *gone, int32_t *stack)
{
    size_t top = 0, rattlers = 0;
    for (size_t i = 0; i < n; i++)
        if (deg[i] < dim + 1) {
            gone[i] = 1;
            stack[top++] = (int32_t)i;
        }
    while (top) {
        size_t i = (size_t)stack[--top];
        rattlers++;
        for (size_t q = off[i]; q < off[i + 1]; q++) {
            if (adj[q] < 0)
                continue;
            size_t j = (size_t)adj[q];
            if (gone[j])
                continue;
            if (--deg[j] < dim + 1) {
                gone[j] = 1;
                stack[top++] = (int32_t)j;
            }
        }
    }
    return rattlers;
}

/* The backbone's contact counts (pairs once, wall contacts once) and mean
 * coordination, from deg after the peel. */
static void backbone_stats(const pk_contact_network *net, size_t n, const int32_t *deg,
                           const uint8_t *gone, pk_contact_stats *cs)
{
    size_t z = 0;
    for (size_t i = 0; i < n; i++)
        if (!gone[i])
            z += (size_t)deg[i];
    size_t walls = 0; /* each pair counted twice in z, each wall contact once */
    for (size_t k = 0; k < net->nwall; k++)
        walls += !gone[net->wi[k]];
    cs->backbone_contacts = (z - walls) / 2 + walls;
    cs->mean_contacts = (double)z / (double)cs->backbone;
}

int pk_contact_network_compute(const pk_box *b, const pk_particles *p, double delta_d,
                               double wall_gap, double tol, pk_contact_network *out,
                               pk_contact_stats *cs)
{
    *cs = (pk_contact_stats){0};
    if (out)
        memset(out, 0, sizeof *out);
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
    pk_contact_network *net = &c.net;
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
    if (c.failed || wall_contacts(b, p, wall_gap, tol, net) != 0)
        goto out;
    for (size_t k = 0; k < net->npair; k++) {
        deg[net->pi[k]]++;
        deg[net->pj[k]]++;
    }
    for (size_t k = 0; k < net->nwall; k++)
        deg[net->wi[k]]++;
    stack = malloc(p->n * sizeof *stack);
    if (build_adjacency(net, p->n, deg, &off, &adj) != 0 || !stack)
        goto out;
    cs->rattlers = peel_rattlers(p->n, p->dim, off, adj, deg, gone, stack);
    cs->contacts = net->npair;
    cs->wall_contacts = net->nwall;
    cs->rattler_fraction = (double)cs->rattlers / (double)p->n;
    cs->backbone = p->n - cs->rattlers;
    if (cs->backbone)
        backbone_stats(net, p->n, deg, gone, cs);
    rc = 0;
    if (out) {
        net->rattler = gone;
        gone = NULL;
        *out = *net;
        memset(net, 0, sizeof *net);
    }
out:
    free(deg);
    free(gone);
    free(off);
    free(adj);
    free(stack);
    pk_contact_network_free(net);
    pk_grid_free(&g);
    return rc;
}

int pk_contact_stats_compute(const pk_box *b, const pk_particles *p, double delta_d, double tol,
                             pk_contact_stats *cs)
{
    return pk_contact_network_compute(b, p, delta_d, 0.5 * delta_d, tol, NULL, cs);
}
