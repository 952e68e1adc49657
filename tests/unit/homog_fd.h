/* homog_fd.h — the analytic tangent Ā against central finite differences of
 * P̄ at fixed topology (shared by the tangent tests; include after
 * homog_fixture.h). */
#ifndef PK_HOMOG_FD_H
#define PK_HOMOG_FD_H

#include "core/homog/homog_tangent.h"
#include "api/solver/sparse_cholmod.h"

/* Largest |FD − Ā| / max|Ā| over the dim² columns of Ā at the fixture's
 * committed state (reached with F0); *asym gets the largest major-symmetry
 * defect, *An = max|Ā|, *skipped the columns whose ±h perturbation switched
 * a contact of the jammed network (not comparable: Ā is the tangent of one
 * topology).  h = 1e-6: truncation O(h²) ~ 1e-12 relative, round-off of
 * the relaxation residual ~1e-13 / h → relative error ≪ 1e-6. */
static inline double fd_tangent_error(fixture *fx, const double F0[9], int dim, const double A[81],
                                      const pk_tangent_info *info, int *skipped, double *asym,
                                      double *An)
{
    *An = 0;
    for (int k = 0; k < 81; k++)
        *An = fmax(*An, fabs(A[k]));
    double worst = 0;
    *asym = 0;
    const double h = 1e-6;
    pk_homog_state tp = {0}, tm = {0};
    pk_homog_step sp, sm;
    for (int c = 0; c < dim; c++)
        for (int d = 0; d < dim; d++) {
            double Fp[9], Fm[9];
            memcpy(Fp, F0, sizeof Fp);
            memcpy(Fm, F0, sizeof Fm);
            Fp[3 * c + d] += h, Fm[3 * c + d] -= h;
            pk_homog_eval(&fx->rve, &fx->o, &fx->s, Fp, &tp, &sp, NULL);
            pk_homog_eval(&fx->rve, &fx->o, &fx->s, Fm, &tm, &sm, NULL);
            /* fixed topology of the jammed network (rattlers, which drift
             * to ε → 0⁺ and may switch, carry no force and are not in Ā) */
            double Aw[81];
            pk_tangent_info ip, im;
            pk_homog_tangent(&fx->rve, &fx->o, &tp, &pk_sparse_cholmod, Aw, &ip);
            pk_homog_tangent(&fx->rve, &fx->o, &tm, &pk_sparse_cholmod, Aw, &im);
            if (ip.jammed_contacts != info->jammed_contacts ||
                im.jammed_contacts != info->jammed_contacts) {
                (*skipped)++;
                continue;
            }
            for (int a = 0; a < dim; a++)
                for (int e = 0; e < dim; e++) {
                    double fd = (sp.P[3 * a + e] - sm.P[3 * a + e]) / (2 * h);
                    double an = A[(3 * a + e) * 9 + 3 * c + d];
                    worst = fmax(worst, fabs(fd - an) / *An);
                    *asym = fmax(*asym, fabs(an - A[(3 * c + d) * 9 + 3 * a + e]) / *An);
                }
        }
    pk_homog_state_free(&tp);
    pk_homog_state_free(&tm);
    return worst;
}

#endif
