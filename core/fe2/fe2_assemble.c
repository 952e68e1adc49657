/* fe2_assemble.c — total-Lagrangian plane-strain assembly of FE² (Meier
 * 2009 (2.10), (2.12)): F̄ = 1 + ∇₀u at each Gauss point, f_int = ∫ P̄·∇₀N,
 * K = ∫ ∇₀N·Ā·∇₀N per unit thickness; the loads.  Contracts: fe2_solver.h,
 * fe2_assemble.h. */
#include "fe2_assemble.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int fe2_gp_buf_init(fe2_gp_buf *b, const pk_fe2_mesh *m)
{
    memset(b, 0, sizeof *b);
    const size_t n = pk_fe2_gauss_count(m), n1 = n ? n : 1;
    b->ngp = n;
    b->elem = malloc(n1 * sizeof *b->elem);
    b->dN = malloc(8 * n1 * sizeof *b->dN);
    b->w = malloc(n1 * sizeof *b->w);
    b->F = calloc(4 * n1, sizeof *b->F);
    b->P = calloc(4 * n1, sizeof *b->P);
    b->A = calloc(16 * n1, sizeof *b->A);
    b->info = calloc(n1, sizeof *b->info);
    b->rc = calloc(n1, sizeof *b->rc);
    b->why = calloc(n1, sizeof *b->why);
    b->res = NULL;
    if (!b->elem || !b->dN || !b->w || !b->F || !b->P || !b->A || !b->info || !b->rc || !b->why) {
        fe2_gp_buf_free(b);
        return -1;
    }
    for (size_t e = 0; e < m->nelem; e++)
        for (size_t g = m->gp_first[e]; g < m->gp_first[e + 1]; g++) {
            double N[4];
            b->elem[g] = e;
            pk_fe2_shape(m, e, (int)(g - m->gp_first[e]), N, &b->dN[8 * g], &b->w[g]);
        }
    return 0;
}

void fe2_gp_buf_free(fe2_gp_buf *b)
{
    free(b->elem), free(b->dN), free(b->w), free(b->F), free(b->P), free(b->A);
    free(b->info), free(b->rc), free(b->why), free(b->res);
    memset(b, 0, sizeof *b);
}

typedef struct round_ctx {
    const pk_fe2_problem *pb;
    fe2_gp_buf *b;
    size_t lo; /* part t is Gauss point lo + t */
    volatile sig_atomic_t *cancel;
} round_ctx;

/* F̄ = 1 + ∇₀u at Gauss point g into its slot. */
static void deformation(const pk_fe2_mesh *m, const double *u, fe2_gp_buf *b, size_t g)
{
    const size_t e = b->elem[g];
    const double *dN = &b->dN[8 * g];
    double *F = &b->F[4 * g];
    F[0] = 1, F[1] = 0, F[2] = 0, F[3] = 1;
    for (int a = 0; a < pk_fe2_elem_nodes(m, e); a++) {
        const double *ua = &u[2 * (size_t)m->conn[4 * e + a]];
        for (int i = 0; i < 2; i++)
            for (int J = 0; J < 2; J++)
                F[2 * i + J] += ua[i] * dN[2 * a + J];
    }
}

/* Part t of a round: Gauss point lo + t alone, into its own slots (its F̄
 * already there). */
static void round_part(void *vctx, int t, int nt)
{
    (void)nt;
    round_ctx *c = vctx;
    const size_t g = c->lo + (size_t)t;
    fe2_gp_buf *b = c->b;
    if (c->cancel && *c->cancel) {
        b->rc[g] = FE2_ROUND_CANCELLED;
        return;
    }
    const double *F = &b->F[4 * g];
    b->why[g][0] = 0;
    memset(&b->info[g], 0, sizeof b->info[g]);
    const double t0 = pk_wall_seconds();
    const double det = F[0] * F[3] - F[1] * F[2];
    if (!(det > 0)) {
        snprintf(b->why[g], FE2_WHY, "det F = %.3g <= 0", det);
        b->rc[g] = FE2_ROUND_FAILED;
        return;
    }
    const pk_fe2_material *mat = c->pb->mat;
    int rc =
        mat->eval(mat->ctx, g, F, &b->P[4 * g], &b->A[16 * g], &b->info[g], b->why[g], FE2_WHY);
    b->rc[g] = rc == 0 ? FE2_ROUND_OK : FE2_ROUND_FAILED;
    if (rc != 0 && !b->why[g][0])
        snprintf(b->why[g], FE2_WHY, "material '%s' failed (%d)", mat->name, rc);
    if (b->info[g].seconds == 0)
        b->info[g].seconds = pk_wall_seconds() - t0;
}

/* Gauss points [lo, hi) at u over pb->par: F̄ of the block, then the parts. */
static void eval_range(const pk_fe2_problem *pb, const double *u, fe2_gp_buf *b, size_t lo,
                       size_t hi, volatile sig_atomic_t *cancel)
{
    for (size_t g = lo; g < hi; g++)
        deformation(pb->mesh, u, b, g);
    round_ctx c = {pb, b, lo, cancel};
    if (hi > lo)
        pk_par_run_parts(pb->par, round_part, &c, (int)(hi - lo));
}

/* The other evaluators' results (outside [lo, hi)) into b's slots; F̄ of
 * every point computed here too, for the state and the record. */
static int fetch_others(const pk_fe2_problem *pb, const double *u, fe2_gp_buf *b, char *why,
                        size_t whylen)
{
    const pk_fe2_distributor *d = pb->dist;
    int rc = d->round_finish(d->ctx, b->res, why, whylen);
    if (rc != PK_FE2_DIST_OK)
        return rc == PK_FE2_DIST_CANCELLED ? FE2_ROUND_CANCELLED : FE2_ROUND_LOST;
    for (size_t g = 0; g < b->ngp; g++) {
        if (g == d->lo)
            g = d->hi;
        if (g >= b->ngp)
            break;
        const pk_fe2_gp_result *r = &b->res[g];
        deformation(pb->mesh, u, b, g);
        memcpy(&b->P[4 * g], r->P, sizeof r->P);
        memcpy(&b->A[16 * g], r->A, sizeof r->A);
        b->info[g] = r->info;
        b->rc[g] = r->rc;
        memcpy(b->why[g], r->why, FE2_WHY);
        b->why[g][FE2_WHY - 1] = 0;
    }
    return FE2_ROUND_OK;
}

int fe2_eval_round(const pk_fe2_problem *pb, const double *u, fe2_gp_buf *b,
                   volatile sig_atomic_t *cancel, char *why, size_t whylen)
{
    const pk_fe2_distributor *d = pb->dist;
    if (d) {
        if (!b->res && !(b->res = calloc(b->ngp ? b->ngp : 1, sizeof *b->res))) {
            snprintf(why, whylen, "out of memory");
            return FE2_ROUND_LOST;
        }
        if (d->round_start(d->ctx, u, 2 * pb->mesh->nnode, why, whylen) != PK_FE2_DIST_OK)
            return FE2_ROUND_LOST;
    }
    eval_range(pb, u, b, d ? d->lo : 0, d ? d->hi : b->ngp, cancel);
    if (d) {
        int rc = fetch_others(pb, u, b, why, whylen);
        if (rc != FE2_ROUND_OK)
            return rc;
    }
    int cancelled = 0;
    for (size_t g = 0; g < b->ngp; g++) {
        if (b->rc[g] == FE2_ROUND_FAILED) {
            double X[2];
            size_t e;
            pk_fe2_gauss_point(pb->mesh, g, X, &e, NULL);
            snprintf(why, whylen, "Gauss point %zu (element %zu, at %.4g, %.4g): %s", g, e, X[0],
                     X[1], b->why[g]);
            return FE2_ROUND_FAILED;
        }
        cancelled |= b->rc[g] == FE2_ROUND_CANCELLED;
    }
    if (cancelled)
        snprintf(why, whylen, "cancelled");
    return cancelled ? FE2_ROUND_CANCELLED : FE2_ROUND_OK;
}

int pk_fe2_eval_block(const pk_fe2_problem *pb, const double *u, size_t lo, size_t hi,
                      pk_fe2_gp_result *res, volatile sig_atomic_t *cancel)
{
    fe2_gp_buf b;
    if (fe2_gp_buf_init(&b, pb->mesh) != 0)
        return -1;
    eval_range(pb, u, &b, lo, hi, cancel);
    for (size_t g = lo; g < hi; g++) {
        pk_fe2_gp_result *r = &res[g - lo];
        memcpy(r->P, &b.P[4 * g], sizeof r->P);
        memcpy(r->A, &b.A[16 * g], sizeof r->A);
        r->info = b.info[g];
        r->rc = b.rc[g];
        memcpy(r->why, b.why[g], sizeof r->why);
    }
    fe2_gp_buf_free(&b);
    return 0;
}

int pk_fe2_commit_block(const pk_fe2_problem *pb, size_t lo, size_t hi)
{
    for (size_t g = lo; g < hi; g++)
        if (pb->mat->commit(pb->mat->ctx, g) != 0)
            return -1;
    return 0;
}

void fe2_internal_force(const pk_fe2_problem *pb, const fe2_gp_buf *b, double *fint)
{
    const pk_fe2_mesh *m = pb->mesh;
    memset(fint, 0, 2 * m->nnode * sizeof *fint);
    for (size_t g = 0; g < b->ngp; g++) {
        const size_t e = b->elem[g];
        const double *dN = &b->dN[8 * g], *P = &b->P[4 * g];
        for (int a = 0; a < pk_fe2_elem_nodes(m, e); a++) {
            double *fa = &fint[2 * (size_t)m->conn[4 * e + a]];
            for (int i = 0; i < 2; i++)
                fa[i] += (P[2 * i] * dN[2 * a] + P[2 * i + 1] * dN[2 * a + 1]) * b->w[g];
        }
    }
}

int fe2_stiffness(const pk_fe2_problem *pb, const fe2_gp_buf *b, const int32_t *map, size_t n,
                  pk_sparse_sym *K)
{
    const pk_fe2_mesh *m = pb->mesh;
    K->n = n;
    K->nnz = 0;
    for (size_t e = 0; e < m->nelem; e++) {
        const int nen = pk_fe2_elem_nodes(m, e);
        double Ke[8][8];
        memset(Ke, 0, sizeof Ke);
        for (size_t g = m->gp_first[e]; g < m->gp_first[e + 1]; g++) {
            const double *dN = &b->dN[8 * g], *A = &b->A[16 * g];
            /* (Ā + Āᵀ)/2: the frictionless RVE tangent has major symmetry
             * up to round-off; the symmetric solver stores one triangle */
            double As[16];
            for (int I = 0; I < 4; I++)
                for (int J = 0; J < 4; J++)
                    As[4 * I + J] = 0.5 * (A[4 * I + J] + A[4 * J + I]);
            for (int a = 0; a < nen; a++)
                for (int i = 0; i < 2; i++)
                    for (int c = 0; c < nen; c++)
                        for (int k = 0; k < 2; k++) {
                            double s = 0;
                            for (int J = 0; J < 2; J++)
                                for (int L = 0; L < 2; L++)
                                    s += dN[2 * a + J] * As[4 * (2 * i + J) + 2 * k + L] *
                                        dN[2 * c + L];
                            Ke[2 * a + i][2 * c + k] += s * b->w[g];
                        }
        }
        int32_t dof[8];
        for (int a = 0; a < nen; a++)
            for (int i = 0; i < 2; i++) {
                const int32_t d = 2 * m->conn[4 * e + a] + i;
                dof[2 * a + i] = map ? map[d] : d;
            }
        for (int p = 0; p < 2 * nen; p++)
            for (int q = p; q < 2 * nen; q++)
                if (dof[p] >= 0 && dof[q] >= 0 && pk_sparse_sym_add(K, dof[p], dof[q], Ke[p][q]))
                    return -1;
    }
    return 0;
}

int pk_fe2_residual(const pk_fe2_problem *pb, const double *u, const double *fext, double *R,
                    pk_sparse_sym *K, char *why, size_t whylen)
{
    fe2_gp_buf b;
    if (fe2_gp_buf_init(&b, pb->mesh) != 0) {
        snprintf(why, whylen, "out of memory");
        return -1;
    }
    int rc = fe2_eval_round(pb, u, &b, NULL, why, whylen);
    if (rc == FE2_ROUND_OK) {
        const size_t ndof = 2 * pb->mesh->nnode;
        fe2_internal_force(pb, &b, R);
        if (fext)
            for (size_t d = 0; d < ndof; d++)
                R[d] -= fext[d];
        if (K && fe2_stiffness(pb, &b, NULL, ndof, K) != 0) {
            snprintf(why, whylen, "out of memory");
            rc = -1;
        }
    }
    fe2_gp_buf_free(&b);
    return rc;
}

void pk_fe2_edge_traction(const pk_fe2_mesh *m, int32_t a, int32_t b, const double t[2], double *f)
{
    /* linear shape functions along the edge: half of t·ℓ to each end */
    const double dx = m->xy[2 * (size_t)b] - m->xy[2 * (size_t)a],
                 dy = m->xy[2 * (size_t)b + 1] - m->xy[2 * (size_t)a + 1];
    const double h = 0.5 * sqrt(dx * dx + dy * dy);
    for (int i = 0; i < 2; i++) {
        f[2 * (size_t)a + i] += h * t[i];
        f[2 * (size_t)b + i] += h * t[i];
    }
}

void pk_fe2_body_force(const pk_fe2_mesh *m, const double bf[2], double *f)
{
    for (size_t e = 0; e < m->nelem; e++)
        for (int q = 0; q < pk_fe2_elem_gauss(m, e); q++) {
            double N[4], dN[8], w;
            pk_fe2_shape(m, e, q, N, dN, &w);
            for (int a = 0; a < pk_fe2_elem_nodes(m, e); a++)
                for (int i = 0; i < 2; i++)
                    f[2 * (size_t)m->conn[4 * e + a] + i] += N[a] * w * bf[i];
        }
}
