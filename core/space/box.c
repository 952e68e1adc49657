/* box.c — the rectangular domain: measure, minimum image, wrapping, ball
 * measure.  Contract: core/space/box.h. */
#include "box.h"

#include <math.h>

double pk_box_measure(const pk_box *b)
{
    double v = 1.0;
    for (int k = 0; k < b->dim; k++)
        v *= b->L[k];
    return v;
}

void pk_box_min_image(const pk_box *b, double d[PK_MAXDIM])
{
    for (int k = 0; k < b->dim; k++)
        if (b->periodic[k])
            d[k] -= b->L[k] * nearbyint(d[k] / b->L[k]);
}

void pk_box_wrap(const pk_box *b, double x[PK_MAXDIM])
{
    for (int k = 0; k < b->dim; k++)
        if (b->periodic[k]) {
            x[k] -= b->L[k] * floor(x[k] / b->L[k]);
            if (x[k] >= b->L[k]) /* floor round-off can leave x == L */
                x[k] = 0.0;
        }
}

double pk_box_dist2(const pk_box *b, const double *a, const double *c)
{
    double d[PK_MAXDIM] = {0, 0, 0};
    for (int k = 0; k < b->dim; k++)
        d[k] = a[k] - c[k];
    pk_box_min_image(b, d);
    double s = 0;
    for (int k = 0; k < b->dim; k++)
        s += d[k] * d[k];
    return s;
}

double pk_ball_measure(int dim, double r)
{
    return dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
}
