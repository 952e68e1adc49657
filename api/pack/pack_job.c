/* pack_job.c — the 'pack' process: JSON inputs to the job struct, plan, run.
 * Contract: api/pack/pack_job.h. */
#include "pack_job.h"
#include "pack_placer.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* + 0.0: a -0 in the job reads as +0 (no -0 in results or messages) */
static double num(json_t *o, const char *key, double dflt)
{
    json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) + 0.0 : dflt;
}

/* An integer field (pk_json_int: 500.0 is 500); a value that is no exact
 * integer in [lo, hi] is an error naming the field (the schema's maxima
 * normally catch it first). */
static long long int_field(json_t *o, const char *key, const char *ptr, long long lo,
                           long long hi, long long dflt, pk_schema_errors *errs)
{
    json_t *v = json_object_get(o, key);
    long long x;
    if (!v)
        return dflt;
    if (pk_json_int(v, &x) != 0 || x < lo || x > hi) {
        char got[32];
        snprintf(got, sizeof got, "%.17g", json_number_value(v));
        pk_schema_errors_add(errs, ptr, "integer", "must be an integer in [%lld, %lld] (got %s)", lo,
                             hi, got);
        return dflt;
    }
    return x;
}

static int grading_from_json(json_t *g, pk_grading *out, int *default_discrete,
                             pk_schema_errors *errs)
{
    const char *type = json_string_value(json_object_get(g, "type"));
    *default_discrete = 0;
    if (!type)
        return -1;
    if (strcmp(type, "sieve") == 0) {
        json_t *s = json_object_get(g, "sizes"), *p = json_object_get(g, "passing");
        size_t n = json_array_size(s);
        if (n != json_array_size(p)) {
            pk_schema_errors_add(errs, "/grading/passing", "sameLength",
                                 "must have one entry per sieve size (%zu sizes, %zu values)", n,
                                 json_array_size(p));
            return -1;
        }
        double sz[PK_PSD_MAX_CLASSES + 1], pc[PK_PSD_MAX_CLASSES + 1];
        if (n > PK_PSD_MAX_CLASSES) {
            pk_schema_errors_add(errs, "/grading/sizes", "maxItems", "at most %d sieves",
                                 PK_PSD_MAX_CLASSES);
            return -1;
        }
        for (size_t i = 0; i < n; i++) {
            sz[i] = json_number_value(json_array_get(s, i));
            pc[i] = json_number_value(json_array_get(p, i));
        }
        for (size_t i = 1; i < n; i++) {
            if (!(sz[i] > sz[i - 1])) {
                char ptr[64];
                snprintf(ptr, sizeof ptr, "/grading/sizes/%zu", i);
                pk_schema_errors_add(errs, ptr, "ascending",
                                     "sieve sizes must be strictly ascending (%g after %g)", sz[i],
                                     sz[i - 1]);
                return -1;
            }
            if (pc[i] < pc[i - 1]) {
                char ptr[64];
                snprintf(ptr, sizeof ptr, "/grading/passing/%zu", i);
                pk_schema_errors_add(errs, ptr, "nonDecreasing",
                                     "cumulative %% passing must not decrease (%g after %g)",
                                     pc[i], pc[i - 1]);
                return -1;
            }
        }
        if (pc[n - 1] != 100) {
            char ptr[64];
            snprintf(ptr, sizeof ptr, "/grading/passing/%zu", n - 1);
            pk_schema_errors_add(errs, ptr, "endsAt100",
                                 "the largest sieve must pass 100 %% (got %g)", pc[n - 1]);
            return -1;
        }
        if (pk_grading_from_sieve(out, sz, pc, (int)n) != 0) {
            pk_schema_errors_add(errs, "/grading", "grading", "%s", pk_psd_error());
            return -1;
        }
        return 0;
    }
    if (strcmp(type, "classes") == 0) {
        json_t *c = json_object_get(g, "classes");
        size_t n = json_array_size(c);
        if (n > PK_PSD_MAX_CLASSES) {
            pk_schema_errors_add(errs, "/grading/classes", "maxItems", "at most %d classes",
                                 PK_PSD_MAX_CLASSES);
            return -1;
        }
        double d[PK_PSD_MAX_CLASSES], share[PK_PSD_MAX_CLASSES], rho[PK_PSD_MAX_CLASSES];
        int mass = 0, vol = 0;
        double total = 0;
        for (size_t i = 0; i < n; i++) {
            json_t *ci = json_array_get(c, i);
            d[i] = num(ci, "d", 0);
            if (json_object_get(ci, "mass_percent")) {
                mass = 1;
                share[i] = num(ci, "mass_percent", 0);
                rho[i] = num(ci, "density", 1);
            } else {
                vol = 1;
                share[i] = num(ci, "volume_percent", 0);
                rho[i] = 1;
            }
            total += share[i];
            for (size_t j = 0; j < i; j++)
                if (d[j] == d[i]) {
                    char ptr[64];
                    snprintf(ptr, sizeof ptr, "/grading/classes/%zu/d", i);
                    pk_schema_errors_add(errs, ptr, "unique", "diameter %g appears twice", d[i]);
                    return -1;
                }
        }
        if (mass && vol) {
            pk_schema_errors_add(errs, "/grading/classes", "consistent",
                                 "use either volume_percent or mass_percent+density for all classes");
            return -1;
        }
        if (!(total > 0)) {
            pk_schema_errors_add(errs, "/grading/classes", "positiveTotal",
                                 "the class percentages sum to zero");
            return -1;
        }
        if (fabs(total - 100) > 0.5) {
            pk_schema_errors_add(errs, "/grading/classes", "sumTo100",
                                 "class percentages must sum to 100 (±0.5), got %g", total);
            return -1;
        }
        if (pk_grading_from_classes(out, d, share, mass ? rho : NULL, (int)n) != 0) {
            pk_schema_errors_add(errs, "/grading", "grading", "%s", pk_psd_error());
            return -1;
        }
        *default_discrete = 1;
        return 0;
    }
    if (strcmp(type, "fuller") == 0)
        return 0; /* built in the plan: its floor is d_min */
    if (strcmp(type, "preset") == 0) {
        if (pk_grading_preset(out, json_string_value(json_object_get(g, "name"))) != 0) {
            pk_schema_errors_add(errs, "/grading/name", "enum", "%s", pk_psd_error());
            return -1;
        }
        return 0;
    }
    return -1;
}

size_t pk_pack_job_from_json(json_t *in, pk_pack_job *job, pk_schema_errors *errs)
{
    size_t before = errs->n;
    memset(job, 0, sizeof *job);
    job->dim = (int)int_field(in, "dim", "/dim", 2, 3, 3, errs);
    const char *unit = json_string_value(json_object_get(in, "unit"));
    snprintf(job->unit, sizeof job->unit, "%s", unit ? unit : "mm");

    json_t *box = json_object_get(json_object_get(in, "domain"), "box");
    json_t *size = json_object_get(box, "size");
    job->box.dim = job->dim;
    if (!box) /* a mesh domain: the placer reports its box (pack_placer.h) */
        ;
    else if (json_array_size(size) != (size_t)job->dim)
        pk_schema_errors_add(errs, "/domain/box/size", "dim",
                             "needs %d edge lengths for dim = %d (got %zu)", job->dim, job->dim,
                             json_array_size(size));
    for (int k = 0; k < job->dim && k < (int)json_array_size(size); k++)
        job->box.L[k] = json_number_value(json_array_get(size, (size_t)k));
    json_t *per = json_object_get(box, "periodic");
    if (json_is_array(per)) {
        if (json_array_size(per) != (size_t)job->dim)
            pk_schema_errors_add(errs, "/domain/box/periodic", "dim",
                                 "needs %d booleans for dim = %d (got %zu)", job->dim, job->dim,
                                 json_array_size(per));
        for (int k = 0; k < job->dim && k < (int)json_array_size(per); k++)
            job->box.periodic[k] = json_is_true(json_array_get(per, (size_t)k));
    } else {
        for (int k = 0; k < job->dim; k++)
            job->box.periodic[k] = json_is_true(per);
    }

    json_t *g = json_object_get(in, "grading");
    int default_discrete = 0;
    grading_from_json(g, &job->grading, &default_discrete, errs);
    const char *sampling = json_string_value(json_object_get(in, "sampling"));
    job->discrete = sampling ? strcmp(sampling, "discrete") == 0 : default_discrete;
    job->d_min = num(in, "d_min", 0);

    const char *gtype = json_string_value(json_object_get(g, "type"));
    if (gtype && strcmp(gtype, "fuller") == 0) {
        double dmax = num(g, "d_max", 0), q = num(g, "q", 0.5);
        if (!(job->d_min > 0))
            pk_schema_errors_add(errs, "/d_min", "required",
                                 "a Fuller curve needs a cut-off diameter d_min");
        else if (job->d_min >= dmax)
            pk_schema_errors_add(errs, "/d_min", "lessThanDmax",
                                 "d_min (%g) must be below d_max (%g)", job->d_min, dmax);
        else if (pk_grading_from_fuller(&job->grading, q, dmax, job->d_min) != 0)
            pk_schema_errors_add(errs, "/grading", "grading", "%s", pk_psd_error());
    }

    json_t *phi = json_object_get(in, "phi");
    if (phi) {
        job->has_phi = 1;
        job->phi = num(phi, "value", 0);
        const char *ref = json_string_value(json_object_get(phi, "refers_to"));
        job->phi_is_mix = ref && strcmp(ref, "mix") == 0;
    }
    job->count = (size_t)int_field(in, "count", "/count", 1, PK_PACK_MAX_COUNT, 0, errs);
    job->delta_d = num(in, "delta_d", 0);
    const char *algo = json_string_value(json_object_get(in, "algorithm"));
    snprintf(job->algorithm, sizeof job->algorithm, "%s", algo ? algo : "rsa");
    const pk_placer *placer = pk_placer_find(job->algorithm);
    if (!placer)
        pk_schema_errors_add(errs, "/algorithm", "enum", "no placer named \"%s\"", job->algorithm);
    else if (!box && !placer->own_sizes)
        pk_schema_errors_add(errs, "/domain", "boxDomain",
                             "algorithm \"%s\" needs a box domain (a mesh needs \"tetfill\")",
                             job->algorithm);
    job->inputs = in;
    job->seed = (uint64_t)int_field(in, "seed", "/seed", 0, 9007199254740991LL, 1, errs);
    job->max_particles = (size_t)int_field(json_object_get(in, "limits"), "max_particles",
                                           "/limits/max_particles", 1, PK_PACK_MAX_COUNT, 20000000,
                                           errs);
    job->wall_time_s = num(json_object_get(in, "limits"), "wall_time_s", 0);
    return errs->n - before;
}

static double class_rep_measure(int dim, double d) { return pk_ball_measure(dim, 0.5 * d); }

/* EDMD growing every diameter until jammed (relative growth) bounds the sizes
 * only by φ <= 1 (core/edmd/edmd.c, spec §3.3d): the largest grain, shell included,
 * may reach (d_max + Δd)·φ_s^(-1/dim), φ_s the shells' fraction at the target
 * sizes.  On a periodic axis that must stay below L/2, or a pair could meet
 * two images of each other (minimum image).  φ_s is bounded below by
 * φ (1 + Δd/d_max)^dim, so the check errs on the refusing side. */
/* EDMD growing the grains themselves until jammed: the given sizes are
 * ratios, the final sizes are set by jamming. */
static int grows_until_jammed(const pk_pack_job *job)
{
    json_t *o = json_object_get(job->inputs, "edmd");
    const char *until = json_string_value(json_object_get(o, "until"));
    const char *growth = json_string_value(json_object_get(o, "growth"));
    const char *maximize = json_string_value(json_object_get(o, "maximize"));
    return !strcmp(job->algorithm, "edmd") && until && !strcmp(until, "jammed") &&
           !(growth && !strcmp(growth, "shell")) && !(maximize && !strcmp(maximize, "delta_d"));
}

static void check_periodic_jamming(const pk_pack_job *job, const pk_pack_plan *plan,
                                   pk_schema_errors *errs)
{
    if (!grows_until_jammed(job))
        return;
    const int dim = job->dim;
    double phi_s = plan->phi_resolved * pow(1 + job->delta_d / plan->d_max, dim);
    double reach = (plan->d_max + job->delta_d) * pow(fmax(phi_s, 1e-300), -1.0 / dim);
    for (int k = 0; k < dim; k++) {
        if (!job->box.periodic[k] || reach < 0.5 * job->box.L[k])
            continue;
        char ptr[64];
        snprintf(ptr, sizeof ptr, "/domain/box/size/%d", k);
        double need = pow((plan->d_max + job->delta_d) / (0.5 * job->box.L[k]), dim);
        pk_schema_errors_add(errs, ptr, "periodicJamming",
                             "until jammed the grains may grow to fill the box: the largest could "
                             "reach d = %.4g, over half the periodic edge %g (minimum image); needs "
                             "φ at the target sizes > %.3g (got %.3g): more grains, a walled axis "
                             "or until: target",
                             reach, job->box.L[k], need, phi_s);
        return;
    }
}

size_t pk_pack_plan_make(const pk_pack_job *job, pk_pack_plan *plan, pk_schema_errors *errs)
{
    size_t before = errs->n;
    memset(plan, 0, sizeof *plan);
    plan->scale = 1;
    const pk_placer *own = pk_placer_find(job->algorithm);
    if (own && own->own_sizes) { /* no grading: the placer plans and checks alone */
        plan->phi_resolved = plan->phi_mix = job->has_phi ? job->phi : 0;
        plan->expected_n = (double)job->count;
        if (own->check)
            own->check(job, plan, errs);
        return errs->n - before;
    }
    const pk_grading *g = &job->grading;
    if (g->nclass <= 0)
        return errs->n - before; /* grading errors already reported */
    double d_top = g->cls[0].d_hi > g->cls[0].d_rep ? g->cls[0].d_hi : g->cls[0].d_rep;
    double d_bottom = g->cls[g->nclass - 1].d_lo;

    plan->resolved = *g;
    if (job->d_min > 0) {
        if (job->d_min >= d_top) {
            pk_schema_errors_add(errs, "/d_min", "lessThanDmax",
                                 "d_min (%g) cuts away the whole curve (largest size %g)",
                                 job->d_min, d_top);
            return errs->n - before;
        }
        if (!job->discrete && job->d_min < d_bottom - 1e-12 * d_bottom && g->mass_below > 0) {
            pk_schema_errors_add(errs, "/d_min", "curveRange",
                                 "d_min (%g) is below the smallest sieve (%g) while %.3g %% "
                                 "passes it: the curve says nothing about those sizes",
                                 job->d_min, d_bottom, 100 * g->mass_below);
            return errs->n - before;
        }
        if (pk_grading_truncate(&plan->resolved, job->d_min) != 0) {
            pk_schema_errors_add(errs, "/d_min", "grading", "%s", pk_psd_error());
            return errs->n - before;
        }
    }
    plan->mass_cut = plan->resolved.mass_below;
    double keep = 1 - plan->mass_cut;
    if (!(keep > 0)) {
        pk_schema_errors_add(errs, "/d_min", "grading", "no material left above d_min");
        return errs->n - before;
    }
    double V = pk_box_measure(&job->box);
    const int dim = job->dim;

    /* targets */
    if (job->has_phi) {
        plan->phi_resolved = job->phi_is_mix ? job->phi * keep : job->phi;
        plan->phi_mix = job->phi_is_mix ? job->phi : job->phi / keep;
    }

    /* expected count and mean grain measure */
    double mean_measure = 0; /* expected measure per grain */
    if (job->discrete) {
        double share[PK_PSD_MAX_CLASSES];
        pk_discrete_number_shares(&plan->resolved, dim, share);
        for (int i = 0; i < plan->resolved.nclass; i++)
            mean_measure += share[i] * class_rep_measure(dim, plan->resolved.cls[i].d_rep);
    } else {
        double n1 = pk_grading_expected_count(&plan->resolved, dim, 1.0 / keep, NULL);
        mean_measure = n1 > 0 ? 1.0 / n1 : 0; /* unit resolved measure holds n1 grains */
    }
    if (!(mean_measure > 0)) { /* material is left (keep > 0): the count overflowed */
        pk_schema_errors_add(errs, "/d_min", "maxParticles",
                             "the grading above d_min = %g holds too many grains to count: raise d_min",
                             job->d_min);
        return errs->n - before;
    }
    if (job->count) {
        plan->expected_n = (double)job->count;
        if (job->has_phi) /* Meier: absolute size set by the packing */
            plan->scale = pow(plan->phi_resolved * V / ((double)job->count * mean_measure), 1.0 / dim);
        else {
            plan->phi_resolved = (double)job->count * mean_measure / V;
            plan->phi_mix = plan->phi_resolved / keep;
        }
    } else {
        plan->expected_n = plan->phi_resolved * V / mean_measure;
    }
    double d_max = 0;
    for (int i = 0; i < plan->resolved.nclass; i++) {
        const pk_size_class *c = &plan->resolved.cls[i];
        if (c->mass_fraction > 0)
            d_max = fmax(d_max, job->discrete ? c->d_rep : c->d_hi);
    }
    plan->d_max = d_max * plan->scale;

    if (plan->expected_n > (double)job->max_particles)
        pk_schema_errors_add(errs, job->count ? "/count" : "/phi", "maxParticles",
                             "the job needs about %.4g grains, over the limit of %zu "
                             "(raise limits.max_particles or d_min)",
                             plan->expected_n, job->max_particles);
    if (job->has_phi && !(plan->phi_resolved < 1))
        pk_schema_errors_add(errs, "/phi/value", "resolvedBelow1",
                             "resolved solid fraction %.4g must be < 1", plan->phi_resolved);
    for (int k = 0; k < dim; k++) {
        char ptr[64];
        snprintf(ptr, sizeof ptr, "/domain/box/size/%d", k);
        double need = plan->d_max + job->delta_d;
        if (job->box.periodic[k] && !(job->box.L[k] > 2 * need))
            pk_schema_errors_add(errs, ptr, "periodicSize",
                                 "a periodic edge must exceed 2·(d_max + Δd) = %g (got %g), or a "
                                 "grain would meet two images of another",
                                 2 * need, job->box.L[k]);
        else if (!job->box.periodic[k] && !(job->box.L[k] >= need))
            pk_schema_errors_add(errs, ptr, "wallSize",
                                 "a walled edge must hold the largest grain plus Δd = %g (got %g)",
                                 need, job->box.L[k]);
    }
    if (errs->n == before) {
        /* Grains kept Δd apart carry disjoint shells of diameter d + Δd inside
         * the box widened by Δd/2 at each wall; their measure is at least
         * φ (1 + Δd/d_max)^dim of the box: it must stay below 1 (the field
         * named: Δd when the grains alone fit) */
        double widened = 1;
        for (int k = 0; k < dim; k++)
            widened *= job->box.L[k] / (job->box.L[k] + (job->box.periodic[k] ? 0 : job->delta_d));
        double phi_shell = plan->phi_resolved * widened * pow(1 + job->delta_d / plan->d_max, dim);
        if (!(phi_shell < 1) && !grows_until_jammed(job)) {
            const char *ptr = plan->phi_resolved < 1 && job->delta_d > 0 ? "/delta_d"
                              : job->count && !job->has_phi         ? "/count"
                                                                    : "/phi/value";
            pk_schema_errors_add(errs, ptr, "resolvedBelow1",
                                 "the grains would fill φ = %.4g of the box (%.4g with their gaps "
                                 "Δd): must be < 1",
                                 plan->phi_resolved, phi_shell);
        }
    }
    if (errs->n == before)
        check_periodic_jamming(job, plan, errs);
    const pk_placer *placer = pk_placer_find(job->algorithm);
    if (placer && placer->check && errs->n == before)
        placer->check(job, plan, errs);
    return errs->n - before;
}

void pk_pack_check(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs)
{
    pk_pack_job job;
    if (pk_pack_job_from_json(inputs, &job, errs) != 0)
        return;
    job.service = ctx->service;
    pk_pack_plan plan;
    pk_pack_plan_make(&job, &plan, errs);
}
