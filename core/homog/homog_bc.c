/* homog_bc.c — one macroscopic load step: prescribe by the boundary condition
 * (4.24)/(4.27)/(4.33), relax, homogenize (ch. 5); trial/commit.  Contract: homog_bc.h. */
#include "homog_bc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_contact.h"
#include "core/dem/dem_rattler.h"
#include "homog_speculative.h"
#include "core/space/mat3.h"

void pk_homog_state_free(pk_homog_state *s)
{
    free(s->x);
    free(s->keys);
    free(s->u);
    pk_fric_hist_free(&s->hist);
    memset(s, 0, sizeof *s);
}

int pk_homog_state_copy(pk_homog_state *dst, const pk_homog_state *src)
{
    double *x = realloc(dst->x, 3 * (src->n ? src->n : 1) * sizeof *x);
    if (!x)
        return -1;
    dst->x = x;
    uint64_t *k = realloc(dst->keys, (src->ncontact ? src->ncontact : 1) * sizeof *k);
    if (!k)
        return -1;
    dst->keys = k;
    double *u = realloc(dst->u, (src->n ? src->n : 1) * sizeof *u);
    if (!u)
        return -1;
    dst->u = u;
    if (src->u)
        memcpy(dst->u, src->u, src->n * sizeof *u);
    else
        memset(dst->u, 0, (src->n ? src->n : 1) * sizeof *u);
    if (pk_fric_hist_copy(&dst->hist, &src->hist) != 0)
        return -1;
    dst->n = src->n;
    dst->ncontact = src->ncontact;
    memcpy(dst->F, src->F, sizeof dst->F);
    memcpy(dst->x, src->x, 3 * src->n * sizeof *src->x);
    if (src->ncontact)
        memcpy(dst->keys, src->keys, src->ncontact * sizeof *src->keys);
    return 0;
}

int pk_homog_commit(pk_homog_state *committed, const pk_homog_state *trial)
{
    return pk_homog_state_copy(committed, trial);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Contact keys of the last evaluation, sorted. */
static int collect_keys(const pk_dem_pairs *c, pk_homog_state *s)
{
    size_t n = 0;
    for (size_t p = 0; p < c->n; p++)
        n += c->eps[p] >= 0 && c->len[p] > 0;
    uint64_t *k = realloc(s->keys, (n ? n : 1) * sizeof *k);
    if (!k)
        return -1;
    s->keys = k;
    n = 0;
    for (size_t p = 0; p < c->n; p++)
        if (c->eps[p] >= 0 && c->len[p] > 0)
            k[n++] = (uint64_t)(uint32_t)c->i[p] << 32 | (uint32_t)c->j[p];
    qsort(k, n, sizeof *k, cmp_u64);
    s->ncontact = n;
    return 0;
}

void pk_homog_pairs_setup(pk_dem_pairs *c, const pk_homog_rve *rve, const pk_homog_opts *o)
{
    pk_dem_pairs_stiffness(c, o->E_n_species ? rve->species : NULL, o->E_n_species, o->n_species,
                           o->E_n);
    c->par = o->par;
}

static void geom_of(const pk_homog_rve *rve, pk_dem_geom *g)
{
    memset(g, 0, sizeof *g);
    g->dim = rve->dim;
    g->periodic = rve->periodic;
    memcpy(g->L, rve->L, sizeof g->L);
}

int pk_homog_state_init(const pk_homog_rve *rve, const pk_homog_opts *o, pk_homog_state *s)
{
    memset(s, 0, sizeof *s);
    s->n = rve->n;
    pk_m3_identity(s->F);
    s->x = malloc(3 * (rve->n ? rve->n : 1) * sizeof *s->x);
    s->u = calloc(rve->n ? rve->n : 1, sizeof *s->u);
    if (!s->x || !s->u)
        return -1;
    memcpy(s->x, rve->X, 3 * rve->n * sizeof *s->x);
    pk_dem_geom g;
    geom_of(rve, &g);
    pk_dem_geom_set_F(&g, s->F);
    pk_dem_pairs c = {0};
    pk_homog_pairs_setup(&c, rve, o);
    int rc = pk_dem_pairs_build(&c, &g, s->x, rve->r, rve->n, o->dr.skin);
    if (rc == 0) {
        pk_dem_eval(&c, &g, s->x, rve->r, rve->n, o->E_n, NULL, NULL, NULL);
        rc = collect_keys(&c, s);
    }
    pk_dem_pairs_free(&c);
    return rc;
}

/* formed = in b not in a; broken = in a not in b (both sorted) */
static void diff_keys(const pk_homog_state *a, const pk_homog_state *b, size_t *formed,
                      size_t *broken)
{
    size_t i = 0, j = 0, common = 0;
    while (i < a->ncontact && j < b->ncontact) {
        if (a->keys[i] == b->keys[j])
            common++, i++, j++;
        else if (a->keys[i] < b->keys[j])
            i++;
        else
            j++;
    }
    *formed = b->ncontact - common;
    *broken = a->ncontact - common;
}

/* F̄ as the 3×3 the RVE is deformed by: the 2D embedding
 * [[F11 F12 0] [F21 F22 0] [0 0 1]] in 2D.  -3 unless finite. */
static int embed_F(const double F[9], int dim, double Fm[9])
{
    memcpy(Fm, F, 9 * sizeof *Fm);
    if (dim == 2) {
        Fm[2] = Fm[5] = Fm[6] = Fm[7] = 0;
        Fm[8] = 1;
    }
    for (int k = 0; k < 9; k++)
        if (!isfinite(Fm[k]))
            return -3;
    return 0;
}

/* The trial's starting positions: prescribed grains at F̄X ((4.24), (4.27)₁,
 * corners (4.33)₂); free ones where the committed state left them, moved by
 * F̄ F̄ₙ⁻¹ with the affine predictor.  -3 if F̄ₙ is singular. */
static int prescribe(const pk_homog_rve *rve, const pk_homog_opts *o,
                     const pk_homog_state *committed, const double Fm[9], pk_homog_state *trial)
{
    double Fold_inv[9], Q[9];
    if (pk_m3_inv(committed->F, Fold_inv) == 0)
        return -3;
    pk_m3_mul(Fm, Fold_inv, Q);
    for (size_t i = 0; i < rve->n; i++) {
        double *x = &trial->x[3 * i];
        if (rve->fixed[i])
            pk_m3_vec(Fm, &rve->X[3 * i], x);
        else if (o->affine_predictor) {
            double y[3];
            pk_m3_vec(Q, x, y);
            memcpy(x, y, sizeof y);
        }
        if (rve->dim == 2)
            x[2] = 0;
    }
    return 0;
}

/* Relax the free grains of the trial: with friction (history from the
 * committed state), by the Newton hybrid when asked, else by DR. */
static int relax_trial(const pk_dem_system *sys, const pk_homog_rve *rve, const pk_homog_opts *o,
                       const pk_homog_state *committed, pk_fric_ctx *fc, pk_homog_state *trial,
                       pk_monitor *mon, pk_homog_step *out, pk_fric_totals *ftot)
{
    size_t nfree = 0;
    for (size_t i = 0; i < sys->np; i++)
        nfree += sys->is_free[i];
    if (o->friction) {
        geom_of(rve, &fc->g_n);
        pk_dem_geom_set_F(&fc->g_n, committed->F);
        return pk_homog_relax_fric(sys, trial->x, &o->dr, fc, trial->u, mon, &out->dr, ftot);
    }
    if (o->newton && nfree) {
        out->used_newton = 1;
        const pk_newton_opts no = {o->newton, o->newton_ctx, o->newton_max_iter};
        return pk_homog_newton_speculative(sys, trial->x, &o->dr, &no, mon, &out->dr, &out->newton);
    }
    return pk_homog_relax(sys, trial->x, &o->dr, mon, &out->dr);
}

/* The averaged stresses from S = Σ f ⊗ l over the RVE's volume V:
 * P = (Σ f ⊗ l) F̄⁻ᵗ / V, σ = S / (J V), and σ's skew part. */
static void average_stresses(const double S[9], const double Finv[9], double J, double V,
                             pk_homog_step *out)
{
    double FinvT[9];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            FinvT[3 * a + b] = Finv[3 * b + a];
    pk_m3_mul(S, FinvT, out->P); /* Σ f ⊗ F̄⁻¹l = (Σ f ⊗ l) F̄⁻ᵗ */
    for (int k = 0; k < 9; k++) {
        out->P[k] /= V;
        out->sigma[k] = S[k] / (J * V);
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            out->sigma_skew[3 * a + b] = 0.5 * (out->sigma[3 * a + b] - out->sigma[3 * b + a]);
}

/* Balance checks of the relaxed state from the forces f: |Σ f|, the free
 * grains' residual, the stress from the prescribed grains' reactions (walled
 * RVEs; periodic: P itself) and its relative defect against P. */
static void force_balance(const pk_homog_rve *rve, const double *f, const uint8_t *is_free,
                          pk_homog_step *out)
{
    const int dim = rve->dim;
    double sf[3] = {0, 0, 0}, ff = 0;
    memset(out->P_reaction, 0, sizeof out->P_reaction);
    for (size_t i = 0; i < rve->n; i++) {
        for (int a = 0; a < dim; a++) {
            sf[a] += f[3 * i + a];
            ff += is_free[i] ? f[3 * i + a] * f[3 * i + a] : 0;
        }
        if (rve->fixed[i] && !rve->periodic)
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++)
                    out->P_reaction[3 * a + b] -= f[3 * i + a] * rve->X[3 * i + b] / rve->V;
    }
    if (rve->periodic)
        memcpy(out->P_reaction, out->P, sizeof out->P);
    out->sum_force = sqrt(sf[0] * sf[0] + sf[1] * sf[1] + sf[2] * sf[2]);
    out->free_force = sqrt(ff);
    double dP = 0, nP = 0;
    for (int k = 0; k < 9; k++) {
        dP += (out->P_reaction[k] - out->P[k]) * (out->P_reaction[k] - out->P[k]);
        nP += out->P[k] * out->P[k];
    }
    out->reaction_defect = sqrt(dP) / fmax(sqrt(nP), 1e-300);
}

/* Largest overlap of a contact over the smaller radius of its pair. */
static double max_overlap_ratio(const pk_dem_pairs *c, const double *r)
{
    double m = 0;
    for (size_t p = 0; p < c->n; p++)
        if (c->eps[p] >= 0 && c->len[p] > 0)
            m = fmax(m, c->eps[p] / fmin(r[c->i[p]], r[c->j[p]]));
    return m;
}

int pk_homog_eval(const pk_homog_rve *rve, const pk_homog_opts *o, const pk_homog_state *committed,
                  const double F[9], pk_homog_state *trial, pk_homog_step *out, pk_monitor *mon)
{
    const int dim = rve->dim;
    const size_t n = rve->n;
    memset(out, 0, sizeof *out);
    double Fm[9];
    if (embed_F(F, dim, Fm) != 0)
        return -3;
    pk_dem_geom g;
    geom_of(rve, &g);
    double J = pk_dem_geom_set_F(&g, Fm);
    if (!(J > 0))
        return -3;
    if (o->friction && dim != 2)
        return -4;
    if (pk_homog_state_copy(trial, committed) != 0)
        return -1;
    memcpy(trial->F, Fm, sizeof Fm);
    if (prescribe(rve, o, committed, Fm, trial) != 0)
        return -3;
    uint8_t *is_free = malloc(n ? n : 1);
    double *f = malloc(3 * (n ? n : 1) * sizeof *f);
    uint8_t *rat = malloc(n ? n : 1);
    pk_dem_pairs c = {0};
    pk_homog_pairs_setup(&c, rve, o);
    pk_fric_ctx fc = {
        .law = o->friction, .x_n = committed->x, .u_n = committed->u, .hist_n = &committed->hist};
    pk_fric_totals ftot = {0};
    int rc = 0;
    if (!is_free || !f || !rat) {
        rc = -1;
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        is_free[i] = !rve->fixed[i];
    const pk_dem_system sys = {&c, &g, rve->r, n, o->E_n, is_free};
    rc = relax_trial(&sys, rve, o, committed, &fc, trial, mon, out, &ftot);
    if (rc != 0)
        goto done;

    /* homogenization at the relaxed state */
    double S[9];
    double phi;
    out->contacts = pk_dem_eval(&c, &g, trial->x, rve->r, n, o->E_n, f, &phi, S);
    if (o->friction) { /* tangential forces (7.19) in f and S; σ̄ by (7.26) */
        if (pk_dem_fric_eval(&c, &fc, trial->x, trial->u, rve->r, n, o->E_n, f, NULL, S, &ftot) !=
                0 ||
            pk_fric_hist_collect(&c, &fc, &trial->hist) != 0) {
            rc = -1;
            goto done;
        }
        out->energy_t = ftot.energy;
        out->dissipation = ftot.dissipation;
        out->sliding = ftot.sliding;
    }
    memcpy(out->F, Fm, sizeof Fm);
    out->J = J;
    out->energy = phi;
    out->energy_density = phi / rve->V;
    average_stresses(S, g.Finv, J, rve->V, out);
    force_balance(rve, f, is_free, out);
    out->max_overlap_ratio = max_overlap_ratio(&c, rve->r);
    size_t nr = pk_dem_rattlers(&c, dim, n, is_free, rat);
    if (nr == (size_t)-1) {
        rc = -1;
        goto done;
    }
    out->rattlers = nr;
    out->coordination = n ? 2.0 * (double)out->contacts / (double)n : 0;
    if (collect_keys(&c, trial) != 0) {
        rc = -1;
        goto done;
    }
    diff_keys(committed, trial, &out->formed, &out->broken);
done:
    pk_fric_pairs_free(&fc.w);
    pk_dem_pairs_free(&c);
    free(is_free);
    free(f);
    free(rat);
    return rc;
}
