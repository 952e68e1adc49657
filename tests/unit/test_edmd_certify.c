/* test_edmd_certify.c — the jamming certificate (core/edmd/edmd_rigidity.h)
 * on packings whose rigidity is known: a triangular crystal of disks in a
 * periodic box (3 contacts per disk, rigid up to the two translations) with
 * every gap g·(r_i + r_j); the same crystal with one row of disks shifted
 * apart (a floppy sliding mode: hypostatic); the tolerance ladder's top. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "api/solver/sparse_cholmod.h"
#include "core/edmd/edmd_rigidity.h"

enum { NX = 6, NY = 6 };

/* NX × NY disks of radius 0.5 on a triangular lattice of spacing 1 + g;
 * rows from `loose_row` on are lifted by `lift` and the box is 2·lift
 * taller: two slabs, gaps `lift` at the cut and at the seam. */
static void crystal(double g, int loose_row, double lift, pk_particles *p, pk_box *b)
{
    const double a = 1 + g, h = a * sqrt(3) / 2;
    memset(b, 0, sizeof *b);
    b->dim = 2;
    b->L[0] = NX * a;
    b->L[1] = NY * h + 2 * lift;
    b->periodic[0] = b->periodic[1] = true;
    pk_particles_init(p, 2, NX * NY);
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) {
            double x[3] = {(i + 0.5 * (j % 2)) * a, j * h + (j >= loose_row ? lift : 0), 0};
            pk_particles_push(p, x, 0.5, 0);
        }
}

static pk_rigidity certify(const pk_box *b, const pk_particles *p, double tol0, double *tol)
{
    pk_contact_stats cs;
    pk_rigidity rg;
    CHECK(pk_jam_certify(b, p, 0, 0, tol0, &pk_sparse_cholmod, &cs, &rg, tol) == 0);
    return rg;
}

/* Touching crystal: rigid at the first tolerance, 3N contacts ≥ 2N − 1. */
static void test_touching_crystal_rigid(void)
{
    pk_box b;
    pk_particles p;
    crystal(0, NY, 0, &p, &b);
    double tol;
    pk_rigidity rg = certify(&b, &p, 1e-9, &tol);
    CHECK(rg.rigid && rg.backbone == NX * NY && rg.contacts == 3 * NX * NY);
    CHECK(rg.maxwell_min == 2 * NX * NY - 1 && tol == 1e-9);
    pk_particles_free(&p);
}

/* Gaps of 5·10⁻⁵ from the tolerance of p = 10¹² in 3D (3·10⁻⁹): rigid
 * only at the ladder's top, 10⁻⁴ (decades of 3·10⁻⁹ alone stop at 3·10⁻⁵);
 * gaps of 2·10⁻⁴: no contact, no backbone, not jammed. */
static void test_ladder_reaches_its_top(void)
{
    pk_box b;
    pk_particles p;
    crystal(5e-5, NY, 0, &p, &b);
    double tol;
    pk_rigidity rg = certify(&b, &p, 3e-9, &tol);
    CHECK_MSG(rg.rigid && fabs(tol / PK_JAM_TOL_MAX - 1) < 1e-9, "rigid %d at %g", rg.rigid, tol);
    pk_particles_free(&p);
    crystal(2e-4, NY, 0, &p, &b);
    rg = certify(&b, &p, 3e-9, &tol);
    CHECK(!rg.rigid && rg.backbone == 0 && tol == 3e-9);
    pk_particles_free(&p);
}

/* The upper half lifted by 10⁻² with a gap of 10⁻² at the seam too: two
 * rigid slabs that slide against each other (floppy modes beyond the
 * translations); every disk keeps ≥ 4 contacts and the count holds (84 ≥
 * the Maxwell count 71): only the factorisation catches the slide. */
static void test_sliding_slabs_not_rigid(void)
{
    pk_box b;
    pk_particles p;
    crystal(0, NY / 2, 1e-2, &p, &b);
    double tol;
    pk_rigidity rg = certify(&b, &p, 1e-9, &tol);
    CHECK_MSG(!rg.rigid, "backbone %zu, %zu contacts of %zu, floppy %zu", rg.backbone, rg.contacts,
              rg.maxwell_min, rg.floppy);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_touching_crystal_rigid);
    RUN(test_ladder_reaches_its_top);
    RUN(test_sliding_slabs_not_rigid);
    return check_summary();
}
