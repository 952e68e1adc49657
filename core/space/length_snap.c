/* length_snap.c — lengths rounded to PK_SNAP_BITS significant bits
 * (core/space/length_snap.h). */
#include <math.h>

#include "length_snap.h"

double pk_snap(double v)
{
    if (!isfinite(v) || v == 0)
        return v;
    int e;
    const double m = frexp(v, &e); /* v = m 2^e, 0.5 <= |m| < 1 */
    return ldexp(nearbyint(ldexp(m, PK_SNAP_BITS)), e - PK_SNAP_BITS);
}

double pk_snap_within(double v, double unit, double limit)
{
    double s = pk_snap(v);
    for (int i = 0; i < 4 && s > 0 && s * unit > limit; i++) {
        int e;
        frexp(s, &e);
        s -= ldexp(1, e - PK_SNAP_BITS); /* one step of the lattice down */
    }
    return s;
}
