/* rsa_cover.h — the coarse grains listed per fine cell, for RSA's exact test
 * (internal to core/rsa/rsa.c).
 *
 * A fine grain's overlap test in pk_grid visits a box of cells on every grid
 * level; on the coarse levels (big cells, few grains each) that is most of
 * the test: A16 with Δd 1 mm, 172 mm, 14 cells and 15 grains per test on the
 * two coarse levels against 3 cells and 1.2 grains on the fines' own
 * (docs/perf/rsa-gap.md).  Here every grain with r > r_q is also listed in
 * each cell (of edge 2 r_q + Δd) that its ball B(x_j, r_j + r_q + Δd)
 * meets, as Titscher & Unger register grains in every cell their enlarged
 * box meets (§4), so a query of radius r <= r_q reads the one cell of its
 * point for all of them: a listed j with |x − x_j| < r + r_j + Δd has x
 * inside that ball, so x's cell meets it and lists j. */
#ifndef PK_RSA_COVER_H
#define PK_RSA_COVER_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"

typedef struct pk_rsa_cover_cell {
    int32_t *ids;
    uint32_t n, cap;
} pk_rsa_cover_cell;

typedef struct pk_rsa_cover {
    pk_box box;
    double r_q; /* queries with r <= r_q; grains with r > r_q are listed */
    double gap; /* Δd */
    double h[PK_MAXDIM];
    int64_t n[PK_MAXDIM]; /* cells per axis (1 beyond dim) */
    pk_rsa_cover_cell *cell;
    size_t entries;
} pk_rsa_cover;

/* Cells of edge 2 r_q + gap over box b.  The caller bounds the entries
 * (pk_rsa_cover_cells_of).  0 or -1 (bad input / out of memory). */
int pk_rsa_cover_init(pk_rsa_cover *c, const pk_box *b, double r_q, double gap);
void pk_rsa_cover_free(pk_rsa_cover *c);
/* Cells a grain of radius r would be listed in at most (its ball's box). */
double pk_rsa_cover_cells_of(const pk_box *b, double r_q, double gap, double r);
/* List grain j of p if p->r[j] > r_q.  0 or -1 (out of memory). */
int pk_rsa_cover_add(pk_rsa_cover *c, const pk_particles *p, size_t j);
/* 1 if a listed grain j has |x_j − x| < r + r_j + gap (minimum image);
 * r <= r_q, x inside the box. */
int pk_rsa_cover_hits(const pk_rsa_cover *c, const pk_particles *p, const double x[PK_MAXDIM],
                      double r);

#endif
