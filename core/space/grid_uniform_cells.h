/* grid_uniform_cells.h — cell arithmetic shared by core/space/grid_uniform.c and
 * core/space/grid_cover.c (internal). */
#ifndef PK_GRID_UNIFORM_CELLS_H
#define PK_GRID_UNIFORM_CELLS_H

#include <stdint.h>

#include "grid_uniform.h"

/* floor(v) for |v| < 2^62 without the libm call (SSE2 has no roundsd). */
static inline double ug_fast_floor(double v)
{
    double t = (double)(int64_t)v;
    return t > v ? t - 1 : t;
}

/* Cell coordinate along k, clamped (round-off at L, grains off a wall). */
static inline int32_t ug_coord(const pk_ugrid_level *lv, int k, double xk)
{
    double c = ug_fast_floor(xk * lv->inv_h[k]);
    return c < 0 ? 0 : c >= lv->n[k] ? lv->n[k] - 1 : (int32_t)c;
}

/* c modulo n in [0, n) (periodic cell index). */
static inline int32_t ug_wrap_index(int64_t c, int32_t n)
{
    int64_t m = c % n;
    return (int32_t)(m < 0 ? m + n : m);
}

#endif
