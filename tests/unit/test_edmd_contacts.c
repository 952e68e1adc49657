/* test_edmd_contacts.c — contact network of a finished packing
 * (core/edmd/edmd_contacts.h): a constructed packing whose contacts and rattlers
 * are known, the recursive rattler removal, the pressure-based tolerance. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core/edmd/edmd_contacts.h"

/* 2D, disks of diameter 1 in a large walled box: a hexagon (centre C and
 * ring O0..O5, 12 contacts, C has 6, each Oi 3), X in the notch between O0
 * and O1 (touching both), and Y touching X at gap y_gap·(r_X + r_Y).
 * With Y in contact: Y has 1 contact (rattler), then X drops to 2
 * (rattler, recursively); O0, O1 keep 3.  Backbone: the 7 hexagon disks,
 * z = (6 + 6·3)/7. */
static void hexagon(pk_particles *p, pk_box *b, double y_gap)
{
    memset(b, 0, sizeof *b);
    b->dim = 2;
    b->L[0] = b->L[1] = 20;
    pk_particles_init(p, 2, 9);
    const double cx = 10, cy = 10, h = sqrt(3) / 2;
    double x[3] = {cx, cy, 0};
    pk_particles_push(p, x, 0.5, 0);
    for (int k = 0; k < 6; k++) {
        double a = k * M_PI / 3;
        x[0] = cx + cos(a);
        x[1] = cy + sin(a);
        pk_particles_push(p, x, 0.5, 0);
    }
    /* X: the third corner of the triangle O0 O1 away from C */
    double ox = 0.5 * (cx + cos(0) + cx + cos(M_PI / 3)), oy = 0.5 * (cy + cy + sin(M_PI / 3));
    double ux = ox - cx, uy = oy - cy, un = sqrt(ux * ux + uy * uy);
    x[0] = ox + h * ux / un;
    x[1] = oy + h * uy / un;
    pk_particles_push(p, x, 0.5, 0);
    /* Y straight out from X, away from C */
    double vx = x[0] - cx, vy = x[1] - cy, vn = sqrt(vx * vx + vy * vy);
    x[0] += (1 + y_gap) * vx / vn;
    x[1] += (1 + y_gap) * vy / vn;
    pk_particles_push(p, x, 0.5, 0);
}

static void test_oracle_recursive_rattlers(void)
{
    pk_particles p;
    pk_box b;
    hexagon(&p, &b, 0);
    pk_contact_stats cs;
    CHECK(pk_contact_stats_compute(&b, &p, 0, 1e-9, &cs) == 0);
    CHECK(cs.contacts == 15);
    CHECK(cs.rattlers == 2); /* Y, then X */
    CHECK_NEAR(cs.rattler_fraction, 2.0 / 9, 1e-15);
    CHECK_NEAR(cs.mean_contacts, 24.0 / 7, 1e-12);
    pk_particles_free(&p);
}

/* Y at a gap of 10^-6 (r_X + r_Y): no contact at tolerance 10^-9, a
 * contact at 10^-3. */
static void test_oracle_tolerance(void)
{
    pk_particles p;
    pk_box b;
    hexagon(&p, &b, 1e-6);
    pk_contact_stats cs;
    CHECK(pk_contact_stats_compute(&b, &p, 0, 1e-9, &cs) == 0);
    CHECK(cs.contacts == 14);
    CHECK(cs.rattlers == 2); /* Y (0 contacts), X (2) */
    CHECK(pk_contact_stats_compute(&b, &p, 0, 1e-3, &cs) == 0);
    CHECK(cs.contacts == 15);
    CHECK(cs.rattlers == 2);
    pk_particles_free(&p);
}

/* Nothing but rattlers: z of the (empty) backbone is 0, not the mean
 * degree of all grains (which once read 5.04 beside a rattler fraction 1). */
static void test_all_rattlers(void)
{
    pk_particles p;
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = 2;
    b.L[0] = b.L[1] = 10;
    pk_particles_init(&p, 2, 3);
    for (int k = 0; k < 3; k++) { /* a chain of three: 1, 2, 1 contacts */
        double x[3] = {2 + k, 5, 0};
        pk_particles_push(&p, x, 0.5, 0);
    }
    pk_contact_stats cs;
    CHECK(pk_contact_stats_compute(&b, &p, 0, 1e-9, &cs) == 0);
    CHECK(cs.contacts == 2);
    CHECK(cs.rattlers == 3);
    CHECK(cs.mean_contacts == 0);
    pk_particles_free(&p);
}

/* Tolerance from the reduced pressure: 10^3·dim/p, within [10^-12, 10^-3]. */
static void test_tolerance_from_pressure(void)
{
    CHECK_NEAR(pk_contact_tolerance(3, 1e12), 3e-9, 1e-21);
    CHECK_NEAR(pk_contact_tolerance(2, 1e12), 2e-9, 1e-21);
    CHECK(pk_contact_tolerance(3, 1e5) == 1e-3);
    CHECK(pk_contact_tolerance(3, 0) == 1e-3);
    CHECK(pk_contact_tolerance(3, 1e20) == 1e-12);
}

int main(void)
{
    RUN(test_oracle_recursive_rattlers);
    RUN(test_oracle_tolerance);
    RUN(test_all_rattlers);
    RUN(test_tolerance_from_pressure);
    return check_summary();
}
