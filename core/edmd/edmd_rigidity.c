/* edmd_rigidity.c — Maxwell count and first-order rigidity of the backbone.
 * Contract: core/edmd/edmd_rigidity.h. */
#include "edmd_rigidity.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* K += n nᵀ on the blocks of grains a and b (b < 0: a wall, a's block only). */
static int add_spring(pk_sparse_sym *K, int dim, int32_t a, int32_t b, const double n[3])
{
    for (int x = 0; x < dim; x++)
        for (int y = 0; y < dim; y++) {
            const double v = n[x] * n[y];
            if (v == 0)
                continue;
            const int32_t ra = a * dim + x, ca = a * dim + y;
            if (ra <= ca && pk_sparse_sym_add(K, ra, ca, v) != 0)
                return -1;
            if (b < 0)
                continue;
            const int32_t rb = b * dim + x, cb = b * dim + y;
            if (rb <= cb && pk_sparse_sym_add(K, rb, cb, v) != 0)
                return -1;
            /* off-diagonal block −n nᵀ, stored in the upper triangle */
            const int32_t r = ra < cb ? ra : cb, c = ra < cb ? cb : ra;
            if (pk_sparse_sym_add(K, r, c, -v) != 0)
                return -1;
        }
    return 0;
}

int pk_rigidity_test(const pk_box *b, const pk_particles *p, const pk_contact_network *net,
                     const pk_contact_stats *cs, const pk_sparse_solver *solver, pk_rigidity *rg)
{
    *rg = (pk_rigidity){0};
    const int dim = p->dim;
    for (int k = 0; k < dim; k++)
        rg->trivial += b->periodic[k] != 0;
    rg->backbone = cs->backbone;
    rg->contacts = cs->backbone_contacts;
    if (rg->backbone == 0 || !net->rattler)
        return 0;
    rg->maxwell_min = (size_t)dim * rg->backbone + 1 - (size_t)rg->trivial;
    if (rg->contacts < rg->maxwell_min || !solver)
        return 0;
    /* number the backbone 0..N_b−1 */
    int32_t *id = malloc(p->n * sizeof *id);
    if (!id)
        return -1;
    int32_t nb = 0;
    for (size_t i = 0; i < p->n; i++)
        id[i] = net->rattler[i] ? -1 : nb++;
    pk_sparse_sym K = {.n = (size_t)nb * (size_t)dim};
    int rc = -1;
    for (size_t k = 0; k < net->npair; k++) {
        const int32_t a = id[net->pi[k]], c = id[net->pj[k]];
        if (a >= 0 && c >= 0 && add_spring(&K, dim, a, c, &net->normal[3 * k]) != 0)
            goto out;
    }
    for (size_t k = 0; k < net->nwall; k++) {
        const int32_t a = id[net->wi[k]];
        double n[3] = {0, 0, 0};
        n[net->waxis[k]] = 1;
        if (a >= 0 && add_spring(&K, dim, a, -1, n) != 0)
            goto out;
    }
    /* pin grain 0 along the periodic axes: removes exactly the translations */
    for (int k = 0; k < dim; k++)
        if (b->periodic[k] && pk_sparse_sym_add(&K, k, k, 1.0) != 0)
            goto out;
    pk_sparse_info info;
    pk_sparse_factor *f = solver->factor(&K, &info);
    if (info.status == PK_SPARSE_FAILED)
        goto out;
    if (f)
        solver->release(f);
    rg->tested = 1;
    rg->floppy = info.nzero + info.nneg;
    rg->rigid = rg->floppy == 0;
    rc = 0;
out:
    pk_sparse_sym_free(&K);
    free(id);
    return rc;
}

/* One tolerance: the network, then its test. */
static int certify_at(const pk_box *b, const pk_particles *p, double delta_d, double wall_gap,
                      double tol, const pk_sparse_solver *solver, pk_contact_stats *cs,
                      pk_rigidity *rg)
{
    pk_contact_network net;
    if (pk_contact_network_compute(b, p, delta_d, wall_gap, tol, &net, cs) != 0)
        return -1;
    int rc = pk_rigidity_test(b, p, &net, cs, solver, rg);
    pk_contact_network_free(&net);
    return rc;
}

int pk_jam_certify(const pk_box *b, const pk_particles *p, double delta_d, double wall_gap,
                   double tol0, const pk_sparse_solver *solver, pk_contact_stats *cs,
                   pk_rigidity *rg, double *tol_used)
{
    *tol_used = tol0;
    if (certify_at(b, p, delta_d, wall_gap, tol0, solver, cs, rg) != 0)
        return -1;
    for (double tol = tol0; !rg->rigid && tol < PK_JAM_TOL_MAX;) {
        tol = fmin(10 * tol, PK_JAM_TOL_MAX);
        pk_contact_stats c2;
        pk_rigidity r2;
        if (certify_at(b, p, delta_d, wall_gap, tol, solver, &c2, &r2) != 0)
            return -1;
        if (r2.rigid) {
            *cs = c2;
            *rg = r2;
            *tol_used = tol;
        }
    }
    return 0;
}
