/* dem_eval.c — the contact evaluation's entry points (pk_dem_eval,
 * pk_dem_eval_forces): serial or threaded; contract: dem_contact.h. */
#include "dem_contact.h"

#include <string.h>

#include "dem_internal.h"

static size_t eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9], int keep)
{
    if (S)
        memset(S, 0, 9 * sizeof *S);
    pk_dem_pairs_fit_images(c, g, x);
    keep = keep || energy || S;
    size_t nc;
    if (pk_dem_eval_threaded(c, g, x, r, np, E, f, energy, S, keep, &nc))
        return nc;
    if (f)
        memset(f, 0, 3 * np * sizeof *f);
    return pk_dem_eval_serial(c, g, x, r, E, f, energy, S, keep);
}

size_t pk_dem_eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9])
{
    return eval(c, g, x, r, np, E, f, energy, S, 1);
}

int pk_dem_forces_store = 0;

size_t pk_dem_eval_forces(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                          size_t np, double E, double *f)
{
    return eval(c, g, x, r, np, E, f, NULL, NULL, pk_dem_forces_store);
}
