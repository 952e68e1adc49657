#include "gap_audit.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct {
    double x;     /* sweep coordinate (may be an image shifted by ±L) */
    size_t i;     /* grain index */
    int image;    /* 1 = the periodic image at x + L */
} sweep_item;

static int cmp_sweep(const void *a, const void *b)
{
    double xa = ((const sweep_item *)a)->x, xb = ((const sweep_item *)b)->x;
    return (xa > xb) - (xa < xb);
}

int pk_gap_audit(const pk_box *b, const pk_particles *p, double required, double tol,
                 double horizon, pk_gap_report *rep)
{
    *rep = (pk_gap_report){.min_gap = horizon, .min_pair = {SIZE_MAX, SIZE_MAX},
                           .min_wall_gap = INFINITY};
    const int dim = b->dim;
    double rmax = 0;
    for (size_t i = 0; i < p->n; i++)
        rmax = fmax(rmax, p->r[i]);

    /* Wall clearances. */
    for (size_t i = 0; i < p->n; i++)
        for (int k = 0; k < dim; k++) {
            if (b->periodic[k])
                continue;
            double c = fmin(p->x[3 * i + k], b->L[k] - p->x[3 * i + k]) - p->r[i];
            rep->min_wall_gap = fmin(rep->min_wall_gap, c);
            if (c < 0.5 * required - tol)
                rep->walls_below++;
        }

    /* Sweep along x; on a periodic x axis grains near x = 0 get an image at
     * x + L so that pairs across the seam are met exactly once. */
    double reach = 2 * rmax + horizon;
    size_t cap = p->n * 2 + 1, m = 0;
    sweep_item *s = malloc(cap * sizeof *s);
    if (!s)
        return -1;
    for (size_t i = 0; i < p->n; i++) {
        s[m++] = (sweep_item){p->x[3 * i], i, 0};
        if (b->periodic[0] && p->x[3 * i] < reach)
            s[m++] = (sweep_item){p->x[3 * i] + b->L[0], i, 1};
    }
    qsort(s, m, sizeof *s, cmp_sweep);
    for (size_t a = 0; a < m; a++) {
        size_t i = s[a].i;
        for (size_t c = a + 1; c < m && s[c].x - s[a].x < p->r[i] + rmax + horizon; c++) {
            size_t j = s[c].i;
            if (j == i || (s[a].image && s[c].image))
                continue; /* two images: the originals meet the same pair */
            double d2 = 0;
            for (int k = 0; k < dim; k++) {
                double d = k == 0 ? s[c].x - s[a].x : p->x[3 * j + k] - p->x[3 * i + k];
                if (k > 0 && b->periodic[k])
                    d -= b->L[k] * nearbyint(d / b->L[k]);
                d2 += d * d;
            }
            double gap = sqrt(d2) - p->r[i] - p->r[j];
            if (gap >= horizon)
                continue;
            /* With L > 2·reach (the callers' periodic-box rule) each pair is
             * met once; in a narrower box a pair may be counted twice, which
             * only affects the statistics, never min_gap. */
            rep->pairs_checked++;
            if (gap < rep->min_gap) {
                rep->min_gap = gap;
                rep->min_pair[0] = i < j ? i : j;
                rep->min_pair[1] = i < j ? j : i;
            }
            if (gap < required - tol)
                rep->pairs_below++;
        }
    }
    free(s);
    return 0;
}
