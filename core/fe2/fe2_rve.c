/* fe2_rve.c — the DEM RVE at the Gauss points of FE²: trial evaluation,
 * audit, tangent, commit.  Contract: fe2_rve.h. */
#include "fe2_rve.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/homog/homog_audit.h"
#include "core/homog/homog_tangent.h"

/* in-plane index (11, 12, 21, 22) → the 3D-embedded index a·3 + b */
static const int EMB[4] = {0, 1, 3, 4};

size_t pk_fe2_rve_index(const pk_fe2_rve *m, size_t g) { return g % m->nrve; }

static const char *eval_error(int rc)
{
    switch (rc) {
    case -1: return "out of memory";
    case -2: return "periodic box too small for this F";
    case -3: return "det F <= 0 or not finite";
    default: return "evaluation refused";
    }
}

static int rve_eval(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                    pk_fe2_gp_info *info, char *why, size_t whylen)
{
    pk_fe2_rve *m = ctx;
    const pk_homog_rve *rve = &m->rve[pk_fe2_rve_index(m, g)];
    const double F3[9] = {F[0], F[1], 0, F[2], F[3], 0, 0, 0, 1};
    pk_homog_step st;
    int rc = pk_homog_eval(rve, &m->o, &m->committed[g], F3, &m->trial[g], &st, NULL);
    if (rc != 0) {
        snprintf(why, whylen, "RVE: %s", eval_error(rc));
        return 1;
    }
    pk_homog_audit au;
    if (pk_homog_audit_step(rve, &m->o, &m->trial[g], &st, &au)) {
        char what[200];
        pk_homog_audit_describe(&au, &st, what, sizeof what);
        snprintf(why, whylen, "RVE relaxation: %s", what);
        return 1;
    }
    double A3[81];
    pk_tangent_info ti;
    rc = pk_homog_tangent(rve, &m->o, &m->trial[g], m->solver, A3, &ti);
    if (rc != 0) {
        if (rc == 1)
            snprintf(why, whylen, "RVE tangent: jammed block %s",
                     pk_sparse_status_name(ti.block.status));
        else
            snprintf(why, whylen, "RVE tangent: %s",
                     rc == -3 ? "friction (no analytic tangent)" : eval_error(rc));
        return 1;
    }
    for (int I = 0; I < 4; I++) {
        P[I] = st.P[EMB[I]];
        for (int J = 0; J < 4; J++)
            A[4 * I + J] = A3[9 * EMB[I] + EMB[J]];
    }
    if (info) {
        memset(info, 0, sizeof *info);
        info->energy = st.energy_density;
        info->coordination = st.coordination;
        info->rattlers = st.rattlers;
        info->relax_iter = st.dr.iterations;
    }
    return 0;
}

static int rve_commit(void *ctx, size_t g)
{
    pk_fe2_rve *m = ctx;
    return pk_homog_commit(&m->committed[g], &m->trial[g]) == 0 ? 0 : -1;
}

pk_fe2_material pk_fe2_rve_material(pk_fe2_rve *m)
{
    pk_fe2_material mat = {"rve", m, rve_eval, rve_commit};
    return mat;
}

int pk_fe2_rve_init(pk_fe2_rve *m, const pk_homog_rve *rve, size_t nrve, const pk_homog_opts *o,
                    const pk_sparse_solver *solver, size_t ngp, pk_monitor *mon, char *err,
                    size_t errlen)
{
    memset(m, 0, sizeof *m);
    if (nrve == 0) {
        snprintf(err, errlen, "no RVE");
        return -1;
    }
    m->nrve = nrve, m->ngp = ngp, m->rve = rve, m->o = *o, m->solver = solver;
    m->committed = calloc(ngp ? ngp : 1, sizeof *m->committed);
    m->trial = calloc(ngp ? ngp : 1, sizeof *m->trial);
    m->start = calloc(nrve, sizeof *m->start);
    m->P0 = calloc(4 * nrve, sizeof *m->P0);
    pk_homog_state s0 = {0}, relaxed = {0};
    if (!m->committed || !m->trial || !m->start || !m->P0) {
        snprintf(err, errlen, "out of memory");
        goto fail;
    }
    const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (size_t k = 0; k < nrve; k++) {
        if (pk_homog_state_init(&rve[k], o, &s0) != 0) {
            snprintf(err, errlen, "out of memory");
            goto fail;
        }
        int rc = pk_homog_eval(&rve[k], o, &s0, I3, &relaxed, &m->start[k], mon);
        pk_homog_state_free(&s0);
        if (rc != 0) {
            snprintf(err, errlen, "RVE %zu at F = 1: %s", k, eval_error(rc));
            goto fail;
        }
        pk_homog_audit au;
        if (pk_homog_audit_step(&rve[k], o, &relaxed, &m->start[k], &au)) {
            char what[200];
            pk_homog_audit_describe(&au, &m->start[k], what, sizeof what);
            snprintf(err, errlen, "RVE %zu relaxed at F = 1: %s", k, what);
            goto fail;
        }
        for (int I = 0; I < 4; I++)
            m->P0[4 * k + I] = m->start[k].P[EMB[I]];
        for (size_t g = k; g < ngp; g += nrve)
            if (pk_homog_state_copy(&m->committed[g], &relaxed) != 0) {
                snprintf(err, errlen, "out of memory");
                goto fail;
            }
    }
    pk_homog_state_free(&relaxed);
    m->o.par = NULL;
    m->o.newton_ctx = NULL;
    return 0;
fail:
    pk_homog_state_free(&s0);
    pk_homog_state_free(&relaxed);
    pk_fe2_rve_free(m);
    return -1;
}

void pk_fe2_rve_free(pk_fe2_rve *m)
{
    for (size_t g = 0; m->committed && g < m->ngp; g++)
        pk_homog_state_free(&m->committed[g]);
    for (size_t g = 0; m->trial && g < m->ngp; g++)
        pk_homog_state_free(&m->trial[g]);
    free(m->committed), free(m->trial), free(m->start), free(m->P0);
    memset(m, 0, sizeof *m);
}
