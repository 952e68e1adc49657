/* bench/anchor_certify — packd's jamming certificate on a packing made by
 * another program (PackingGeneration, built outside the repository; see
 * docs/perf/edmd.md "Anchor under packd's certificate").
 *
 * PACKD_ANCHOR_DIR=DIR names a finished PackingGeneration folder:
 *   generation.conf  "Particles count: N" and "Packing size: Lx Ly Lz"
 *                    (3D, periodic: "Boundaries mode: 1");
 *   packing.xyzd     N records of x, y, z, d (little-endian doubles);
 *   packing.nfo      "Theoretical Porosity: ε0" and "Final Porosity: ε": the
 *                    stored diameters are the nominal ones, the final ones are
 *                    d·((1 − ε)/(1 − ε0))^(1/3) (PackingGeneration's README,
 *                    "Note on final diameters").
 * PACKD_ANCHOR_P (default 1e12) is the reduced pressure the packing was
 * stopped at: it sets the first tolerance (pk_contact_tolerance).  Prints
 *   bench=anchor_certify n=N phi=F min_gap_rel=G tol=T contacts=C backbone=B
 *         maxwell_min=M floppy=K rattlers=R z=Z rigid=yes|no
 * for each tolerance of the ladder 10^-12 … 10^-3, then the certificate
 * (pk_jam_certify, as `until: jammed` gives it):
 *   bench=anchor_certify verdict certified=yes|no tol=T z=Z rattlers=R
 * min_gap_rel: the smallest surface gap over r_i + r_j (negative: overlap).
 * Without PACKD_ANCHOR_DIR (as in `make bench`) it says so and exits 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/edmd/edmd_contacts.h"
#include "core/edmd/edmd_rigidity.h"
#include "core/space/box.h"
#include "core/space/particles.h"
#include "api/solver/sparse_cholmod.h"

/* The number after `key` in the text file path, or NAN. */
static double conf_value(const char *path, const char *key, int index)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NAN;
    char line[512];
    double v = NAN;
    while (fgets(line, sizeof line, f)) {
        const char *s = strstr(line, key);
        if (!s)
            continue;
        s += strlen(key);
        for (int k = 0; k <= index; k++) {
            char *end;
            v = strtod(s, &end);
            if (end == s) {
                v = NAN;
                break;
            }
            s = end;
        }
        break;
    }
    fclose(f);
    return v;
}

/* Smallest (|x_i − x_j| − r_i − r_j)/(r_i + r_j) over pairs closer than
 * twice the largest diameter (minimum image; a plain cell-free scan over the
 * pairs of a sweep along x, sorted). */
static const pk_particles *sort_p;
static int cmp_idx(const void *a, const void *b)
{
    double xa = sort_p->x[3 * *(const size_t *)a], xb = sort_p->x[3 * *(const size_t *)b];
    return (xa > xb) - (xa < xb);
}

static double min_gap_rel(const pk_box *b, const pk_particles *p)
{
    size_t n = p->n, *ord = malloc(n * sizeof *ord);
    double rmax = 0, best = INFINITY;
    if (!ord)
        return NAN;
    for (size_t i = 0; i < n; i++) {
        ord[i] = i;
        rmax = fmax(rmax, p->r[i]);
    }
    sort_p = p;
    qsort(ord, n, sizeof *ord, cmp_idx);
    const double reach = 2 * rmax, L0 = b->L[0];
    for (size_t a = 0; a < n; a++)
        for (size_t s = 1; s < n; s++) {
            const size_t i = ord[a], j = ord[(a + s) % n];
            double dx0 = p->x[3 * j] - p->x[3 * i];
            if (a + s >= n)
                dx0 += L0;
            if (dx0 > reach)
                break;
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                double dx = p->x[3 * j + k] - p->x[3 * i + k];
                dx -= b->L[k] * round(dx / b->L[k]);
                d2 += dx * dx;
            }
            const double rs = p->r[i] + p->r[j];
            best = fmin(best, (sqrt(d2) - rs) / rs);
        }
    free(ord);
    return best;
}

/* The packing of dir into b and p (final diameters); 0 or -1. */
static int read_anchor(const char *dir, pk_box *b, pk_particles *p)
{
    char conf[1024], xyzd[1024], nfo[1024];
    snprintf(conf, sizeof conf, "%s/generation.conf", dir);
    snprintf(xyzd, sizeof xyzd, "%s/packing.xyzd", dir);
    snprintf(nfo, sizeof nfo, "%s/packing.nfo", dir);
    const double n = conf_value(conf, "Particles count:", 0);
    const double mode = conf_value(conf, "Boundaries mode:", 0);
    const double eps0 = conf_value(nfo, "Theoretical Porosity:", 0);
    const double eps = conf_value(nfo, "Final Porosity:", 0);
    if (!(n > 0) || mode != 1 || !(eps0 > 0) || !(eps > 0)) {
        fprintf(stderr,
                "anchor_certify: %s: need a periodic (mode 1) generation.conf and a "
                "packing.nfo with both porosities\n",
                dir);
        return -1;
    }
    memset(b, 0, sizeof *b);
    b->dim = 3;
    for (int k = 0; k < 3; k++) {
        b->L[k] = conf_value(conf, "Packing size:", k);
        b->periodic[k] = true;
        if (!(b->L[k] > 0))
            return -1;
    }
    const double scale = cbrt((1 - eps) / (1 - eps0));
    FILE *f = fopen(xyzd, "rb");
    if (!f || pk_particles_init(p, 3, (size_t)n) != 0) {
        if (f)
            fclose(f);
        return -1;
    }
    for (size_t i = 0; i < (size_t)n; i++) {
        double rec[4];
        if (fread(rec, sizeof rec, 1, f) != 1) { /* a little-endian host is assumed */
            fclose(f);
            return -1;
        }
        double x[3];
        for (int k = 0; k < 3; k++)
            x[k] = rec[k] - b->L[k] * floor(rec[k] / b->L[k]);
        pk_particles_push(p, x, 0.5 * rec[3] * scale, 0);
    }
    fclose(f);
    return 0;
}

int main(void)
{
    const char *dir = getenv("PACKD_ANCHOR_DIR");
    if (!dir || !*dir) {
        printf("bench=anchor_certify skipped (set PACKD_ANCHOR_DIR to a finished "
               "PackingGeneration folder)\n");
        return 0;
    }
    const char *ps = getenv("PACKD_ANCHOR_P");
    const double pressure = ps ? atof(ps) : 1e12;
    pk_box b;
    pk_particles p = {0};
    if (read_anchor(dir, &b, &p) != 0)
        return 1;
    double vol = 0;
    for (size_t i = 0; i < p.n; i++)
        vol += pk_ball_measure(3, p.r[i]);
    const double phi = vol / pk_box_measure(&b), gmin = min_gap_rel(&b, &p);
    for (double tol = 1e-12; tol < 2e-3; tol *= 10) {
        pk_contact_network net;
        pk_contact_stats cs;
        pk_rigidity rg = {0};
        if (pk_contact_network_compute(&b, &p, 0, 0, tol, &net, &cs) != 0 ||
            pk_rigidity_test(&b, &p, &net, &cs, &pk_sparse_cholmod, &rg) != 0)
            return 1;
        pk_contact_network_free(&net);
        printf("bench=anchor_certify n=%zu phi=%.5f min_gap_rel=%.3g tol=%.0e contacts=%zu "
               "backbone=%zu maxwell_min=%zu floppy=%zu rattlers=%.4f z=%.3f rigid=%s\n",
               p.n, phi, gmin, tol, rg.contacts, rg.backbone, rg.maxwell_min, rg.floppy,
               cs.rattler_fraction, cs.mean_contacts, rg.rigid ? "yes" : "no");
    }
    pk_contact_stats cs;
    pk_rigidity rg;
    double tol = pk_contact_tolerance(3, pressure);
    if (pk_jam_certify(&b, &p, 0, 0, tol, &pk_sparse_cholmod, &cs, &rg, &tol) != 0)
        return 1;
    printf("bench=anchor_certify verdict p=%.3g certified=%s tol=%.2g z=%.3f rattlers=%.4f\n",
           pressure, rg.rigid ? "yes" : "no", tol, cs.mean_contacts, cs.rattler_fraction);
    pk_particles_free(&p);
    return 0;
}
