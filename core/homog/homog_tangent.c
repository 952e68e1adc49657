/* homog_tangent.c — the macroscopic tangent Ā = dP̄/dF̄ by static
 * condensation (ch. 6, (6.18)–(6.20)).  Contract: homog_tangent.h. */
#include "homog_tangent.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_contact.h"
#include "core/dem/dem_rattler.h"
#include "homog_stiffness.h"
#include "core/space/mat3.h"
#include "core/base/progress.h"

/* Number the DOFs of the jammed free grains (dim each; -1: prescribed or
 * rattler).  Returns their count. */
static size_t number_dofs(size_t n, int dim, const uint8_t *is_free, const uint8_t *rat,
                          int32_t *dof)
{
    size_t nd = 0;
    for (size_t i = 0; i < n; i++)
        dof[i] = is_free[i] && !rat[i] ? (int32_t)(dim * nd++) : -1;
    return nd * (size_t)dim;
}

/* What the contacts of the jammed grains add up: A_FF (dim-embedded 9×9),
 * K_II and B (column-major nd × dim²). */
typedef struct tangent_sums {
    double AFF[81];
    pk_sparse_sym K;
    double *Bm;
    size_t nd;
} tangent_sums;

/* Contact p (H_c = −k_c, G_c = F̄⁻¹(l − x_j^free + x_i^free)) adds
 * H_c ⊗̄ (G_c ⊗ G_c) to A_FF (6.7), its K_II blocks, and ±H_c G_c to B's rows
 * of its free grains.  -1 when out of memory. */
static int add_contact(const pk_dem_pairs *c, size_t p, double E, const double *x,
                       const uint8_t *is_free, const double Finv[9], const int32_t *dof, int dim,
                       tangent_sums *t)
{
    size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
    const double *l = &c->l[3 * p];
    double H[9], q[3], G[3];
    pk_homog_pair_hessian(pk_dem_pair_E(c, p, E), c->len[p], c->eps[p], l, H);
    /* G = F⁻¹(l − x_j[free] + x_i[free]) */
    for (int a = 0; a < 3; a++)
        q[a] = l[a] - (is_free[j] ? x[3 * j + a] : 0) + (is_free[i] ? x[3 * i + a] : 0);
    pk_m3_vec(Finv, q, G);
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++)
            for (int cc = 0; cc < dim; cc++)
                for (int d = 0; d < dim; d++)
                    t->AFF[(3 * a + b) * 9 + 3 * cc + d] += H[3 * a + cc] * G[b] * G[d];
    /* K_II blocks; B rows ±H G */
    int32_t di = dof[i], dj = dof[j];
    int rc = pk_homog_add_pair_K(&t->K, dim, di, dj, H) != 0 ? -1 : 0;
    const size_t nd = t->nd;
    for (int al = 0; al < dim; al++)
        for (int ga = 0; ga < dim; ga++)
            for (int de = 0; de < dim; de++) {
                double v = H[3 * ga + al] * G[de];
                int col = ga * dim + de;
                if (dj >= 0)
                    t->Bm[(size_t)col * nd + (size_t)(dj + al)] += v;
                if (di >= 0)
                    t->Bm[(size_t)col * nd + (size_t)(di + al)] -= v;
            }
    return rc;
}

/* Ā = (A_FF − Bᵀ Y) / V with Y = K_II⁻¹ B ((6.18)–(6.20)), 3D-embedded. */
static void condense(const tangent_sums *t, const double *Y, int dim, double V, double A[81])
{
    const size_t nd = t->nd;
    memset(A, 0, 81 * sizeof *A);
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++)
            for (int cc = 0; cc < dim; cc++)
                for (int d = 0; d < dim; d++) {
                    int I = a * dim + b, J = cc * dim + d;
                    double s2 = 0; /* (Bᵀ K⁻¹ B)_IJ */
                    for (size_t k = 0; k < nd; k++)
                        s2 += t->Bm[(size_t)I * nd + k] * Y[(size_t)J * nd + k];
                    A[(3 * a + b) * 9 + 3 * cc + d] =
                        (t->AFF[(3 * a + b) * 9 + 3 * cc + d] - s2) / V;
                }
}

int pk_homog_tangent(const pk_homog_rve *rve, const pk_homog_opts *o, const pk_homog_state *s,
                     const pk_sparse_solver *solver, double A[81], pk_tangent_info *info)
{
    const int dim = rve->dim;
    const size_t n = rve->n;
    const double E = o->E_n;
    double t0 = pk_wall_seconds();
    memset(info, 0, sizeof *info);
    if (o->friction) /* no frictional tangent (none derived in ch. 7); see -3 */
        return -3;
    pk_dem_geom g = {.dim = dim, .periodic = rve->periodic};
    memcpy(g.L, rve->L, sizeof g.L);
    if (!(pk_dem_geom_set_F(&g, s->F) > 0))
        return -1;
    pk_dem_pairs c = {0};
    pk_homog_pairs_setup(&c, rve, o);
    int rc = pk_dem_pairs_build(&c, &g, s->x, rve->r, n, o->dr.skin);
    if (rc != 0)
        return rc;
    pk_dem_eval(&c, &g, s->x, rve->r, n, E, NULL, NULL, NULL);
    uint8_t *is_free = malloc(n ? n : 1), *rat = malloc(n ? n : 1);
    int32_t *dof = malloc((n ? n : 1) * sizeof *dof);
    double *Y = NULL;
    tangent_sums t;
    memset(&t, 0, sizeof t);
    pk_sparse_factor *fac = NULL;
    if (!is_free || !rat || !dof) {
        rc = -1;
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        is_free[i] = !rve->fixed[i];
    if (pk_dem_rattlers(&c, dim, n, is_free, rat) == (size_t)-1) {
        rc = -1;
        goto done;
    }
    const size_t nd = number_dofs(n, dim, is_free, rat, dof);
    t.nd = t.K.n = info->free_dofs = nd;
    const int m = dim * dim;
    t.Bm = calloc((nd ? nd : 1) * (size_t)m, sizeof *t.Bm); /* column-major nd × m */
    Y = calloc((nd ? nd : 1) * (size_t)m, sizeof *Y);
    if (!t.Bm || !Y) {
        rc = -1;
        goto done;
    }
    for (size_t p = 0; p < c.n; p++) {
        if (!(c.eps[p] >= 0) || !(c.len[p] > 0))
            continue;
        if (rat[c.i[p]] || rat[c.j[p]])
            continue; /* jammed contacts only (4.35) */
        info->jammed_contacts++;
        if ((rc = add_contact(&c, p, E, s->x, is_free, g.Finv, dof, dim, &t)) != 0)
            goto done;
    }
    if (nd > 0) {
        fac = solver->factor(&t.K, &info->block);
        if (info->block.status == PK_SPARSE_FAILED) {
            rc = -1;
            goto done;
        }
        if (info->block.status != PK_SPARSE_OK) {
            rc = 1;
            goto done;
        }
        if (solver->solve(fac, (size_t)m, t.Bm, Y) != 0) {
            rc = -1;
            goto done;
        }
    }
    condense(&t, Y, dim, rve->V, A);
done:
    if (fac)
        solver->release(fac);
    pk_sparse_sym_free(&t.K);
    pk_dem_pairs_free(&c);
    free(is_free);
    free(rat);
    free(dof);
    free(t.Bm);
    free(Y);
    info->seconds = pk_wall_seconds() - t0;
    return rc;
}
