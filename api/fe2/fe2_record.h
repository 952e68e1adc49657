/* fe2_record.h — what an fe2 run records per converged load step (the
 * macro fields, the Gauss points' RVE summaries, reactions, dilatancy) and
 * per Newton solve (the residual sequences), and its layout in the result
 * file under /observables/fe2 (docs/result-format.md, "fe2 results"). */
#ifndef PK_FE2_RECORD_H
#define PK_FE2_RECORD_H

#include <stddef.h>
#include <stdint.h>

#include "api/results/h5_observables.h"
#include "api/results/h5_result.h"
#include "api/results/h5_units.h"
#include "core/fe2/fe2_fields.h"
#include "core/fe2/fe2_solver.h"
#include "fe2_job.h"

/* The unit of an fe2 observable ("fe2/piola_stress") in u, or NULL. */
const char *pk_fe2_unit_of(const char *name, const pk_units *u);

typedef struct pk_fe2_dbuf {
    double *v;
    size_t n, cap;
} pk_fe2_dbuf;

typedef struct pk_fe2_record {
    const pk_fe2_setup *s;
    size_t ngp, nstep, nmicro, ngrain;
    const size_t *micro_gp;
    /* per converged step */
    pk_fe2_dbuf step, time, stage, cuts; /* step numbers as doubles until written */
    pk_fe2_dbuf u, x, F, P, sigma, mises, mises_elem;
    pk_fe2_dbuf energy, coordination, rattlers, relax_iter;
    pk_fe2_dbuf reaction, area, dilatancy, micro_x;
    /* per Newton solve (part of a load step) and per iteration */
    pk_fe2_dbuf part_step, part_t0, part_t1, part_n, part_abs0, part_conv;
    pk_fe2_dbuf it_part, it_res, it_eta;
    double area0;
} pk_fe2_record;

int pk_fe2_record_init(pk_fe2_record *r, const pk_fe2_setup *s, const size_t *micro_gp,
                       size_t nmicro, size_t ngrain);
void pk_fe2_record_free(pk_fe2_record *r);

/* The Newton solves of load step `step` (converged or not).  0 / −1. */
int pk_fe2_record_newton(pk_fe2_record *r, size_t step, const pk_fe2_step_report *rep);

/* A converged load step: number, time (stage + fraction), stage, cuts, the
 * state, and the deformed centres of the output Gauss points' RVEs
 * (micro_pos[i] → [ngrain][3] or NULL).  0 / −1. */
int pk_fe2_record_step(pk_fe2_record *r, size_t step, double time, size_t stage, int cuts,
                       const pk_fe2_state *st, const double *const *micro_pos);

/* Everything under /observables/fe2.  0 / −1. */
int pk_fe2_record_write(pk_h5 *h, const pk_fe2_record *r, const pk_units *u);

#endif
