/* rsa_cover.c — coarse grains listed per fine cell.  Contract: rsa_cover.h. */
#include "rsa_cover.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/grow.h"

#define MAX_CELLS ((uint64_t)1 << 31)
/* cells per axis a listed ball may span (pk_rsa_cover_cells_of says more
 * for a larger one, so the caller's budget keeps it out) */
#define AXIS_CAP 256

static double cell_edge(double r_q, double gap)
{
    return 2 * r_q + gap;
}

int pk_rsa_cover_init(pk_rsa_cover *c, const pk_box *b, double r_q, double gap)
{
    memset(c, 0, sizeof *c);
    if (!b || b->dim < 2 || b->dim > 3 || !(r_q > 0) || !(gap >= 0))
        return -1;
    c->box = *b;
    c->r_q = r_q;
    c->gap = gap;
    double want = cell_edge(r_q, gap), cells = 1;
    for (int k = 0; k < PK_MAXDIM; k++) {
        c->n[k] = 1;
        c->h[k] = 1;
        if (k >= b->dim)
            continue;
        double m = b->periodic[k] ? floor(b->L[k] / want) : ceil(b->L[k] / want);
        if (!(m >= 1))
            m = 1;
        if (!(m < (double)MAX_CELLS))
            return -1;
        c->n[k] = (int64_t)m;
        /* periodic: n cells tile L exactly; walled: n·h >= L */
        c->h[k] = b->periodic[k] ? b->L[k] / m : fmax(want, b->L[k] / m);
        cells *= m;
    }
    if (!(cells < (double)MAX_CELLS))
        return -1;
    c->cell = calloc((size_t)cells, sizeof *c->cell);
    return c->cell ? 0 : -1;
}

void pk_rsa_cover_free(pk_rsa_cover *c)
{
    if (c->cell) {
        size_t cells = (size_t)(c->n[0] * c->n[1] * c->n[2]);
        for (size_t i = 0; i < cells; i++)
            free(c->cell[i].ids);
    }
    free(c->cell);
    memset(c, 0, sizeof *c);
}

double pk_rsa_cover_cells_of(const pk_box *b, double r_q, double gap, double r)
{
    double h = cell_edge(r_q, gap), cells = 1;
    for (int k = 0; k < b->dim; k++) {
        double span = floor(2 * (r + r_q + gap) * (1 + 1e-9) / h) + 2;
        if (span >= AXIS_CAP)
            return INFINITY;
        cells *= fmin(ceil(b->L[k] / h), span);
    }
    return cells;
}

static inline int64_t cell_coord(const pk_rsa_cover *c, int k, double xk)
{
    int64_t i = (int64_t)floor(xk / c->h[k]);
    if (c->box.periodic[k]) {
        i %= c->n[k];
        return i < 0 ? i + c->n[k] : i;
    }
    return i < 0 ? 0 : (i >= c->n[k] ? c->n[k] - 1 : i);
}

/* A cell index of axis k from an unwrapped one (walled axes: already in range). */
static inline int64_t wrap_index(const pk_rsa_cover *c, int k, int64_t i)
{
    if (!c->box.periodic[k])
        return i;
    i %= c->n[k];
    return i < 0 ? i + c->n[k] : i;
}

static int push(pk_rsa_cover_cell *cl, int32_t j)
{
    if (cl->n == cl->cap) {
        size_t cap = pk_grow_cap(cl->cap, (size_t)cl->n + 1, 4);
        const pk_grow_item item[] = {PK_GROW_ITEM(cl->ids, 1)};
        if (cap > UINT32_MAX || pk_grow(item, 1, cap) != 0)
            return -1;
        cl->cap = (uint32_t)cap;
    }
    cl->ids[cl->n++] = j;
    return 0;
}

/* Per axis k, the cells [lo, hi] (unwrapped on periodic axes) the ball of
 * radius R around x meets and the squared distances d2[i - lo] from x to
 * each cell's interval; a periodic axis whose range would wrap onto itself
 * takes all cells at distance 0. */
static int64_t axis_cells(const pk_rsa_cover *c, int k, double xk, double R, int64_t *lo,
                          double *d2, int64_t cap)
{
    int64_t a = (int64_t)floor((xk - R) / c->h[k]), b = (int64_t)floor((xk + R) / c->h[k]);
    if (c->box.periodic[k] && b - a + 1 >= c->n[k]) {
        *lo = 0;
        for (int64_t i = 0; i < c->n[k] && i < cap; i++)
            d2[i] = 0;
        return c->n[k];
    }
    if (!c->box.periodic[k]) {
        a = a < 0 ? 0 : a;
        b = b > c->n[k] - 1 ? c->n[k] - 1 : b;
    }
    *lo = a;
    int64_t m = 0;
    for (int64_t i = a; i <= b && m < cap; i++, m++) {
        double s = c->h[k] * (double)i, e = s + c->h[k];
        /* the edge cells of a walled axis reach past the box */
        if (!c->box.periodic[k] && i == 0)
            s = -INFINITY;
        if (!c->box.periodic[k] && i == c->n[k] - 1)
            e = INFINITY;
        double d = xk < s ? s - xk : (xk > e ? xk - e : 0);
        d2[m] = d * d;
    }
    return m;
}


int pk_rsa_cover_add(pk_rsa_cover *c, const pk_particles *p, size_t j)
{
    double r = p->r[j];
    if (!(r > c->r_q))
        return 0;
    const double *x = &p->x[3 * j];
    /* listed where the ball reaches (a hair wider: round-off only adds a
     * test, never loses one) */
    double R = (r + c->r_q + c->gap) * (1 + 1e-12);
    double R2 = R * R;
    int64_t lo[PK_MAXDIM] = {0, 0, 0}, m[PK_MAXDIM] = {1, 1, 1};
    double d2[PK_MAXDIM * AXIS_CAP];
    d2[2 * AXIS_CAP] = 0;
    for (int k = 0; k < c->box.dim; k++) {
        m[k] = axis_cells(c, k, x[k], R, &lo[k], &d2[k * AXIS_CAP], AXIS_CAP);
        if (m[k] >= AXIS_CAP)
            return -1; /* the caller's budget keeps balls below this */
    }
    int rc = 0;
    for (int64_t iz = 0; iz < m[2] && rc == 0; iz++) {
        double dz = d2[2 * AXIS_CAP + iz];
        int64_t cz = c->box.dim == 3 ? wrap_index(c, 2, lo[2] + iz) : 0;
        for (int64_t iy = 0; iy < m[1] && rc == 0; iy++) {
            double dzy = dz + d2[AXIS_CAP + iy];
            if (dzy >= R2)
                continue;
            int64_t cy = wrap_index(c, 1, lo[1] + iy);
            size_t base = (size_t)((cz * c->n[1] + cy) * c->n[0]);
            for (int64_t ix = 0; ix < m[0]; ix++) {
                if (dzy + d2[ix] >= R2)
                    continue;
                int64_t cx = wrap_index(c, 0, lo[0] + ix);
                if (push(&c->cell[base + (size_t)cx], (int32_t)j) != 0) {
                    rc = -1;
                    break;
                }
                c->entries++;
            }
        }
    }
    return rc;
}

int pk_rsa_cover_hits(const pk_rsa_cover *c, const pk_particles *p, const double x[PK_MAXDIM],
                      double r)
{
    size_t lin = 0;
    for (int k = c->box.dim - 1; k >= 0; k--)
        lin = lin * (size_t)c->n[k] + (size_t)cell_coord(c, k, x[k]);
    const pk_rsa_cover_cell *cl = &c->cell[lin];
    for (uint32_t s = 0; s < cl->n; s++) {
        size_t j = (size_t)cl->ids[s];
        const double *xj = &p->x[3 * j];
        double d2 = 0;
        for (int k = 0; k < c->box.dim; k++) {
            double d = xj[k] - x[k];
            if (c->box.periodic[k] && fabs(d) > 0.5 * c->box.L[k])
                d -= c->box.L[k] * nearbyint(d / c->box.L[k]);
            d2 += d * d;
        }
        double s2 = r + p->r[j] + c->gap;
        if (d2 < s2 * s2)
            return 1;
    }
    return 0;
}
