#include "pack_job.h"
#include "pack_placer.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static double num(json_t *o, const char *key, double dflt)
{
    json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : dflt;
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
    job->dim = (int)json_integer_value(json_object_get(in, "dim"));
    if (job->dim != 2 && job->dim != 3)
        job->dim = (int)num(in, "dim", 3);
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
    json_t *count = json_object_get(in, "count");
    job->count = count ? (size_t)json_integer_value(count) : 0;
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
    job->seed = json_object_get(in, "seed") ? (uint64_t)json_integer_value(json_object_get(in, "seed")) : 1;
    job->max_particles = (size_t)num(json_object_get(in, "limits"), "max_particles", 2e7);
    job->wall_time_s = num(json_object_get(in, "limits"), "wall_time_s", 0);
    return errs->n - before;
}

static double class_rep_measure(int dim, double d) { return pk_ball_measure(dim, 0.5 * d); }

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
    if (!(mean_measure > 0)) {
        pk_schema_errors_add(errs, "/grading", "grading", "the grading holds no grains above d_min");
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
                             "the job needs about %.0f grains, over the limit of %zu "
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
