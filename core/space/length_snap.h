/* length_snap.h — lengths in a unit of the job, rounded so that the same job
 * in another length unit computes the same bits.
 *
 * The placers that construct or fly grains (tet filling, EDMD) are chaotic at
 * the last bit: a job whose lengths differ by one rounding (scaled by 1e6, or
 * by 1 + 1e-15) ends at another φ within the spread over seeds (tet fill
 * 0.626–0.632).  Lengths divided by a length of the job (r_min, a box edge)
 * differ between units by a few roundings; kept to PK_SNAP_BITS significant
 * bits they are the same numbers, unless a value lies within those roundings
 * of a midpoint (chance ~1e-7 per value). */
#ifndef PK_LENGTH_SNAP_H
#define PK_LENGTH_SNAP_H

/* 30 bits: a length moves by at most 2^-31 ≈ 4.7e-10 of itself, far below the
 * tolerances (tet fill ε = 1e-4 of r_min); the rounding between units (a few
 * 2^-53) decides the bits in a fraction 2^-22 of the values. */
#define PK_SNAP_BITS 30

/* v rounded to PK_SNAP_BITS significant bits (nearest, ties to even); 0, inf
 * and NaN unchanged. */
double pk_snap(double v);

/* The largest value on the lattice of pk_snap(v) at or below it whose
 * product with unit does not exceed limit (a box edge in a unit, mapped back
 * inside the job's edge limit). */
double pk_snap_within(double v, double unit, double limit);

#endif
