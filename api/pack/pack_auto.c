/* pack_auto.c — "algorithm": "auto": the rule and its record; the contract
 * is in pack_auto.h. */
#include "pack_auto.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pack_placer.h"

/* RSA's reach against the size spread d_max/d_min: the highest target φ_eff,
 * on a grid 0.02 apart, that 3 seeds all placed (periodic box, N^F = 10^6,
 * open draws; bench/presets/presets.py rsa_reach, docs/presets.md).
 * Ascending spread per dim. */
static const struct {
    int dim;
    double spread, phi;
} reach[] = {
    {2, 1, 0.52}, {2, 5, 0.66}, /* equal disks; Meier's quartz sand (continuous) */
    {3, 1, 0.36}, {3, 2, 0.44}, /* equal spheres; two classes d, d/2 */
    {3, 4, 0.58}, {3, 8, 0.66}, /* A16 above 4 mm; Fuller (A16: 0.68) above 2 mm */
};

double pk_auto_rsa_reach(int dim, double spread)
{
    const size_t n = sizeof reach / sizeof *reach;
    double x = log(fmax(spread, 1));
    size_t prev = n;
    for (size_t i = 0; i < n; i++) {
        if (reach[i].dim != dim)
            continue;
        if (x <= log(reach[i].spread)) {
            if (prev == n)
                return reach[i].phi;
            double x0 = log(reach[prev].spread), x1 = log(reach[i].spread);
            return reach[prev].phi + (reach[i].phi - reach[prev].phi) * (x - x0) / (x1 - x0);
        }
        prev = i;
    }
    return prev < n ? reach[prev].phi : 0; /* beyond the widest measured: its reach */
}

/* d_max/d_min of the grains the plan draws and the target φ_eff with each
 * grain's Δd/2 shell (measure-weighted (1 + Δd/d)^dim over the classes). */
static void grading_figures(const pk_pack_job *job, const pk_pack_plan *plan, double *spread,
                            double *phi_shell)
{
    const pk_grading *g = &plan->resolved;
    double lo = INFINITY, hi = 0, w = 0, shell = 0;
    for (int c = 0; c < g->nclass; c++) {
        const pk_size_class *k = &g->cls[c];
        if (!(k->mass_fraction > 0))
            continue;
        double a = job->discrete ? k->d_rep : k->d_lo, b = job->discrete ? k->d_rep : k->d_hi;
        lo = fmin(lo, a);
        hi = fmax(hi, b);
        double d = sqrt(a * b) * plan->scale;
        w += k->mass_fraction;
        shell += k->mass_fraction * pow(1 + job->delta_d / d, job->dim);
    }
    *spread = hi > 0 && lo > 0 ? hi / lo : 1;
    *phi_shell = plan->phi_resolved * (w > 0 ? shell / w : 1);
}

static void choose(pk_pack_job *job, const char *algorithm, const char *fmt, double a, double b)
{
    snprintf(job->algorithm, sizeof job->algorithm, "%s", algorithm);
    snprintf(job->choice.reason, sizeof job->choice.reason, fmt, a, b);
}

size_t pk_pack_auto_resolve(json_t *inputs, pk_pack_job *job, pk_pack_plan *plan,
                            pk_schema_errors *errs)
{
    if (!job->choice.requested || job->choice.reason[0])
        return 0; /* not asked, or decided without the plan (pk_pack_job_from_json) */
    double spread, phi_shell;
    grading_figures(job, plan, &spread, &phi_shell);
    const double thr =
        fmin(PK_AUTO_BREAK_EVEN, pk_auto_rsa_reach(job->dim, spread) - PK_AUTO_REACH_MARGIN);
    job->choice.threshold = thr;
    job->choice.phi_shell = phi_shell;
    job->choice.spread = spread;
    if (phi_shell < thr) {
        choose(job, "rsa",
               "target φ_eff with the Δd shells %.4g below the threshold %.4g: RSA reaches it "
               "quickly",
               phi_shell, thr);
        return 0;
    }
    choose(job, "edmd",
           "target φ_eff with the Δd shells %.4g at or above the threshold %.4g: beyond RSA's "
           "quick reach, EDMD grows the grains to it",
           phi_shell, thr);
    const pk_placer *p = pk_placer_find("edmd");
    memset(&job->opt, 0, sizeof job->opt);
    size_t n = pk_options_fill(p->options, inputs, &job->opt, errs);
    return n + pk_pack_plan_make(job, plan, errs);
}

json_t *pk_pack_auto_json(const pk_pack_job *job)
{
    if (!job->choice.requested)
        return NULL;
    json_t *o = json_pack("{s:s,s:s}", "algorithm", job->algorithm, "reason", job->choice.reason);
    if (!isnan(job->choice.threshold)) {
        json_object_set_new(o, "threshold", json_real(job->choice.threshold));
        json_object_set_new(o, "phi_target_shell", json_real(job->choice.phi_shell));
        json_object_set_new(o, "size_spread", json_real(job->choice.spread));
        json_object_set_new(o, "break_even", json_real(PK_AUTO_BREAK_EVEN));
    }
    return o;
}
