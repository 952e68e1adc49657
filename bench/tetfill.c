/* bench/tetfill.c — Jerier's mesh filling: cost per sphere vs mesh size
 * (flat = linear, his Fig. 8a at φ₀ = 0.6), 10⁵ spheres (bar < 10 s), 10⁶
 * spheres with PACKD_BENCH_LARGE=1 (bar < 2 min, < 2 GiB), and the R sweep
 * on the Gmsh cube of 1127 tets (his Fig. 4a/7a: 1112 tets) to saturation,
 * with the default contact rule and with Jerier's ("touching", gap <= 0), each
 * also in the paper's order of steps (7a after 4–6, "paper_order"). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "core/mesh/mesh.h"
#include "api/mesh/mesh_io.h"
#include "core/tetfill/tetfill.h"
#include "core/tetfill/tetfill_stats.h"

static double max_rss_mib(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_maxrss / 1024.0;
}

/* A walled cube of edge L, r ∈ [0.1, 0.3] (R = 3), mesh edge ≈ 8 r̄. */
static int box_case(const char *name, double L, double phi0, size_t n0)
{
    pk_mesh m;
    char err[256];
    double E[3] = {L, L, L};
    if (pk_mesh_box(&m, E, 8 * 0.2 / 1.282, 0, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    pk_tetfill_params prm;
    pk_tetfill_defaults(&prm);
    prm.r_min = 0.1;
    prm.r_max = 0.3;
    prm.phi_target = phi0;
    prm.n_target = n0;
    pk_particles p;
    pk_particles_init(&p, 3, 1024);
    pk_tetfill_stats st;
    clock_t c0 = clock();
    int rc = pk_tetfill(&m, &prm, NULL, &p, &st);
    /* CPU time too: the machine is shared, wall time is noisy */
    double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    printf("bench=tetfill case=%s tets=%zu spheres=%zu phi=%.4f reason=%s seconds=%.3f cpu_s=%.3f "
           "cpu_us_per_sphere=%.2f spheres_per_cpu_s=%.0f max_rss_mib=%.0f\n",
           name, m.ntet, p.n, st.phi, pk_stop_reason_name(st.reason), st.seconds, cpu,
           1e6 * cpu / (double)(p.n ? p.n : 1), (double)p.n / cpu, max_rss_mib());
    fflush(stdout);
    pk_particles_free(&p);
    pk_mesh_free(&m);
    return rc;
}

/* One R of the sweep with the contact rule of the z_min test (tetfill.h);
 * seed from PACKD_BENCH_SEED (default 0) for the spread over seeds. */
static int sweep_case(const char *path, double R, pk_tetfill_contact_rule rule, int trim_last)
{
    pk_mesh m;
    char err[512];
    if (pk_mesh_read_msh(path, 0, &m, err, sizeof err) != 0 ||
        pk_mesh_check(&m, 0, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    double lo[3] = {m.lo[0], m.lo[1], m.lo[2]};
    pk_mesh_translate(&m, lo);
    pk_tetfill_params prm;
    pk_tetfill_defaults(&prm);
    prm.contact_rule = rule;
    prm.trim_after_loci = trim_last;
    const char *seed = getenv("PACKD_BENCH_SEED");
    prm.seed = seed ? strtoull(seed, NULL, 10) : 0;
    double rbar = m.edge_mean / 8; /* ratio alone: Jerier's rule */
    prm.r_min = 2 * rbar / (R + 1);
    prm.r_max = 2 * rbar - prm.r_min;
    for (int dens = 0; dens <= 1; dens++) {
        prm.densify = dens;
        pk_particles p;
        pk_particles_init(&p, 3, 1024);
        pk_tetfill_stats st;
        pk_tetfill_measures o;
        if (pk_tetfill(&m, &prm, NULL, &p, &st) != 0 ||
            pk_tetfill_measure(&m, &p, prm.r_min, prm.eps, &o) != 0)
            return -1;
        /* z by the three contact definitions of tetfill_stats.h: gap <= ε r_min,
         * <= 1e-9 r_min (tangent), <= 0 (touching) */
        /* with trim_last, "steps1-6" is after 7a and the *_geo figures before it
         * (the paper's state after steps 1–6) */
        printf("bench=tetfill case=sweep%s%s_R%g seed=%llu stage=%s tets=%zu spheres=%zu "
               "n_per_tet=%.2f phi=%.4f z=%.3f z_tangent=%.3f z_touching=%.3f F1=%.4f F2=%.4f "
               "F3=%.4f n_per_tet_geo=%.2f z_tangent_geo=%.3f z_touching_geo=%.3f passes=%d "
               "seconds=%.3f\n",
               trim_last ? "_paper_order" : "",
               rule == PK_TETFILL_CONTACT_TOUCHING ? "_touching" : "", R,
               (unsigned long long)prm.seed, dens ? "saturated" : "steps1-6", m.ntet, p.n,
               (double)p.n / (double)m.ntet, o.phi, o.z_mean, o.z_tangent, o.z_touching,
               o.fabric_eig[0], o.fabric_eig[1], o.fabric_eig[2],
               (double)st.n_geometric / (double)m.ntet, st.geometric.z_tangent,
               st.geometric.z_touching, st.passes, st.seconds);
        fflush(stdout);
        pk_tetfill_measures_free(&o);
        pk_particles_free(&p);
    }
    pk_mesh_free(&m);
    return 0;
}

/* `tetfill [CASE]`: all cases, or only CASE (e.g. under valgrind --tool=callgrind
 * for instruction counts on a shared machine). */
static const char *only;

static int want(const char *name) { return !only || strcmp(only, name) == 0; }

int main(int argc, char **argv)
{
    int rc = 0;
    only = argc > 1 ? argv[1] : NULL;
    /* cost per sphere vs mesh size at φ₀ = 0.6: 8×, 64× the tets */
    if (want("linear_L5"))
        rc |= box_case("linear_L5", 5, 0.6, 0);
    if (want("linear_L10"))
        rc |= box_case("linear_L10", 10, 0.6, 0);
    if (want("linear_L20"))
        rc |= box_case("linear_L20", 20, 0.6, 0);
    /* 10⁵ and 10⁶ spheres, box edge ∝ N^⅓: they end at φ ≈ 0.58 and 0.60 (less
     * boundary loss in the larger box), past the geometric steps, early in 7b */
    if (want("spheres_1e5"))
        rc |= box_case("spheres_1e5", 17, 0, 100000);
    if (getenv("PACKD_BENCH_LARGE") || (only && want("spheres_1e6")))
        rc |= box_case("spheres_1e6", 17 * cbrt(10), 0, 1000000);
    if (only && strncmp(only, "sweep", 5) != 0)
        return rc ? 1 : 0;
    const char *src = getenv("PACKD_SRC");
    char path[4096];
    snprintf(path, sizeof path, "%s/tests/data/meshes/cube41.msh", src ? src : ".");
    /* "sweep": the default contact rule; "sweep_touching": Jerier's (gap <= 0);
     * "sweep_paper_order[_touching]": the same with 7a after steps 4–6 */
    const double R[4] = {2, 3, 5, 7};
    for (int last = 0; last <= 1; last++) {
        for (int i = 0; i < 4 && want(last ? "sweep_paper_order" : "sweep"); i++)
            rc |= sweep_case(path, R[i], PK_TETFILL_CONTACT_TANGENT, last);
        for (int i = 0; i < 4 && want(last ? "sweep_paper_order_touching" : "sweep_touching"); i++)
            rc |= sweep_case(path, R[i], PK_TETFILL_CONTACT_TOUCHING, last);
    }
    return rc ? 1 : 0;
}
