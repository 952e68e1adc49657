/* dem_internal.h — the calls between the files of the contact evaluation
 * (dem_pairs.c, dem_eval.c, dem_eval_loops.c, dem_eval_par.c); not used
 * outside core/dem.  Calls run one way: dem_eval.c → dem_pairs.c,
 * dem_eval_par.c, dem_eval_loops.c; dem_eval_par.c → dem_eval_loops.c. */
#ifndef PK_DEM_INTERNAL_H
#define PK_DEM_INTERNAL_H

#include <stddef.h>

#include "dem_contact.h"

/* dem_pairs.c: on a periodic geometry, form the candidates' lattice shifts
 * afresh at x when g is not the geometry they were formed under (another F̄
 * or L on the same list). */
void pk_dem_pairs_fit_images(pk_dem_pairs *c, const pk_dem_geom *g, const double *x);

/* dem_eval_loops.c: the serial evaluation of every candidate (f, when not
 * NULL, zeroed by the caller; S zeroed).  keep = 0 only for the forces
 * alone: the 2D lanes may leave c->l, len, eps as they were. */
size_t pk_dem_eval_serial(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                          double E, double *f, double *energy, double S[9], int keep);

/* dem_eval_loops.c: phase A of the threaded evaluation over candidates
 * [pa, pb) (whole runs of i): the serial loop's geometry, each candidate's
 * force on i in c->fa (+0 when open) and the runs' sums added to f (zeroed
 * there by the caller).  Returns the number of contacts. */
size_t pk_dem_eval_part(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                        double E, double *f, size_t pa, size_t pb, int keep);

/* dem_eval_par.c: the evaluation on c->par when the call qualifies (a pool
 * of two or more threads, f != NULL, at least pk_dem_par_min_pairs
 * candidates in build order): 1 with the contact count in *nc, the serial
 * results bit for bit; 0 (nothing done) otherwise.  S zeroed by the caller. */
int pk_dem_eval_threaded(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                         size_t np, double E, double *f, double *energy, double S[9], int keep,
                         size_t *nc);

#endif
