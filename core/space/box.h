/* box.h — the rectangular domain: 2D or 3D, each axis periodic or walled.
 * Origin at 0, edges L[k].  In 2D the third axis is unused (L[2] = 0). */
#ifndef PK_BOX_H
#define PK_BOX_H

#include <stdbool.h>

#define PK_MAXDIM 3

typedef struct pk_box {
    int dim;                  /* 2 or 3 */
    double L[PK_MAXDIM];      /* edge lengths */
    bool periodic[PK_MAXDIM]; /* true = periodic axis, false = walls at 0 and L */
} pk_box;

/* Area (2D) or volume (3D). */
double pk_box_measure(const pk_box *b);

/* Replace d by its minimum image along the periodic axes. */
void pk_box_min_image(const pk_box *b, double d[PK_MAXDIM]);

/* Wrap a position into [0, L) along periodic axes. */
void pk_box_wrap(const pk_box *b, double x[PK_MAXDIM]);

/* Squared minimum-image distance between two points. */
double pk_box_dist2(const pk_box *b, const double *a, const double *c);

/* Measure of a ball of radius r in dimension dim (π r² or 4/3 π r³). */
double pk_ball_measure(int dim, double r);

#endif
