/* homog_speculative.h — the Newton/DR hybrid (homog_newton.h) with its
 * attempts made speculatively on a second thread when the pair list's pool
 * (s->c->par) has two threads or more; the serial hybrid's step otherwise.
 * Either way the serial hybrid's result, bit for bit. */
#ifndef PK_HOMOG_SPECULATIVE_H
#define PK_HOMOG_SPECULATIVE_H

#include "homog_newton.h"

/* The hybrid solve (homog_newton.h).  Same contract as pk_homog_relax (st
 * describes the DR part, if any, with st->f0 the initial and st->f the final
 * residual of the whole solve); with fewer than two threads the serial step. */
int pk_homog_newton_speculative(const pk_dem_system *s, double *x, const pk_dr_params *prm,
                                const pk_newton_opts *no, pk_monitor *mon, pk_dr_stats *st,
                                pk_newton_stats *ns);

#endif
