/* test_length_snap.c — lengths kept to 30 significant bits
 * (core/space/length_snap.h): a ratio of lengths computed in two units
 * snaps to the same number; a snapped edge maps back inside its wall. */
#include <math.h>

#include "check.h"
#include "core/space/length_snap.h"

/* 0.5/20 and 1.5/20 computed at lengths ×1e-6, ×1, ×1e6 and ×(1 + 1e-15):
 * the raw quotients differ in their last bits, the snapped ones do not. */
static void test_same_bits_in_every_unit(void)
{
    const double scale[] = {1e-6, 1, 1e6, 1 + 1e-15, 3, 0.1};
    const double len[] = {0.5, 1.5, 0.315, 0.05, 16, 2.0 / 3};
    int raw_differ = 0;
    for (int j = 0; j < 6; j++) {
        const double ref = pk_snap(len[j] / 20);
        for (int i = 0; i < 6; i++) {
            const double q = (len[j] * scale[i]) / (20 * scale[i]);
            raw_differ |= q != len[j] / 20;
            CHECK_MSG(pk_snap(q) == ref, "%g at scale %g", len[j], scale[i]);
        }
    }
    CHECK(raw_differ); /* else the test proves nothing */
    CHECK(pk_snap(0) == 0 && isinf(pk_snap(INFINITY)) && pk_snap(0.25) == 0.25);
    CHECK(fabs(pk_snap(0.1) / 0.1 - 1) <= ldexp(1, -31));
}

/* An edge L in a unit ℓ: snapped, its product with ℓ stays <= L. */
static void test_within_the_wall(void)
{
    for (int i = 1; i < 200; i++) {
        const double ell = 0.1 * i + 1e-7, L = 7.3 * ell + 0.013 * i;
        const double s = pk_snap_within(L / ell, ell, L);
        CHECK_MSG(s * ell <= L, "L %.17g ell %.17g", L, ell);
        CHECK(fabs(s - L / ell) <= ldexp(L / ell, -28));
    }
}

int main(void)
{
    RUN(test_same_bits_in_every_unit);
    RUN(test_within_the_wall);
    return check_summary();
}
