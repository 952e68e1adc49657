/* pack_job.c — the 'pack' process's inputs: its option table, the grading
 * and box readers, the feasibility plan and the parse hook (pack_job.h). */
#include "pack_job.h"
#include "pack_auto.h"
#include "pack_placer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define F(m) PK_OPT_FIELD(pk_pack_job, m)
static const char *const sampling_names[] = {"continuous", "discrete", NULL};
static const char *const refers_names[] = {"resolved", "mix", NULL};
static const pk_option pack_rows[] = {
    {"/dim", PK_OPT_INTEGER, F(dim), PK_OPT_IMPLICIT, .dflt = 3, .lo = 2, .hi = 3},
    {"/unit", PK_OPT_STRING, F(unit), .sdefault = "mm"},
    {"/sampling", PK_OPT_ENUM, F(sampling), PK_OPT_IMPLICIT, .dflt = -1, .names = sampling_names},
    {"/d_min", PK_OPT_NUMBER, F(d_min), PK_OPT_IMPLICIT},
    {"/grading/q", PK_OPT_NUMBER, F(fuller_q), PK_OPT_IMPLICIT, .dflt = 0.5},
    {"/grading/d_max", PK_OPT_NUMBER, F(fuller_d_max), PK_OPT_IMPLICIT},
    {"/phi/value", PK_OPT_NUMBER, F(phi), PK_OPT_IMPLICIT},
    {"/phi/refers_to", PK_OPT_ENUM, F(phi_is_mix), PK_OPT_IMPLICIT, .names = refers_names},
    {"/count", PK_OPT_INTEGER, F(count), PK_OPT_IMPLICIT, .lo = 1, .hi = PK_PACK_MAX_COUNT},
    {"/delta_d", PK_OPT_NUMBER, F(delta_d)},
    {"/algorithm", PK_OPT_STRING, F(algorithm), .sdefault = "rsa"},
    {"/quality", PK_OPT_ENUM, F(quality), .dflt = PK_QUALITY_STANDARD, .names = pk_quality_names},
    {"/seed", PK_OPT_INTEGER, F(seed), .dflt = 1, .lo = 0, .hi = 9007199254740991LL},
    {"/limits/max_particles", PK_OPT_INTEGER, F(max_particles), .dflt = 20000000, .lo = 1,
     .hi = PK_PACK_MAX_COUNT},
    {"/limits/wall_time_s", PK_OPT_NUMBER, F(wall_time_s), PK_OPT_IMPLICIT},
};
#undef F
const pk_option_table pk_pack_options =
    PK_OPT_TABLE("pack.inputs.schema.json", pk_pack_job, pack_rows, NULL);

/* An entry of a grading array (+ 0.0: a -0 reads as +0). */
static double entry(json_t *v) { return json_number_value(v) + 0.0; }

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
        if (n < 2) { /* the schema's minItems: a curve needs two sieves */
            pk_schema_errors_add(errs, "/grading/sizes", "minItems",
                                 "needs at least 2 sieve sizes (got %zu)", n);
            return -1;
        }
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
                                     "cumulative %% passing must not decrease (%g after %g)", pc[i],
                                     pc[i - 1]);
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
            json_t *rho_i = json_object_get(ci, "density");
            d[i] = entry(json_object_get(ci, "d"));
            if (json_object_get(ci, "mass_percent")) {
                mass = 1;
                share[i] = entry(json_object_get(ci, "mass_percent"));
                rho[i] = rho_i ? entry(rho_i) : 1;
            } else {
                vol = 1;
                share[i] = entry(json_object_get(ci, "volume_percent"));
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
            pk_schema_errors_add(
                errs, "/grading/classes", "consistent",
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

/* "algorithm": "auto" (pack_auto.h): what is decided before the plan — a mesh
 * takes tetfill, "until": "jammed" edmd; else rsa until the plan's figures
 * decide (pk_pack_auto_resolve). */
static void auto_without_plan(json_t *in, pk_pack_job *job, int box)
{
    job->choice.threshold = job->choice.phi_shell = job->choice.spread = NAN;
    if (strcmp(job->algorithm, "auto") != 0)
        return;
    job->choice.requested = 1;
    const char *until = json_string_value(pk_json_at(in, "/edmd/until"));
    const char *why = !box ? "the domain is a mesh: tet filling is the placer of a mesh"
        : until && !strcmp(until, "jammed")
        ? "edmd.until is jammed: only EDMD grows a packing until it jams"
        : NULL;
    snprintf(job->algorithm, sizeof job->algorithm, "%s",
             !box      ? pk_placer_filling_mesh()->name
                 : why ? "edmd"
                       : "rsa");
    snprintf(job->choice.reason, sizeof job->choice.reason, "%s", why ? why : "");
}

size_t pk_pack_job_from_json(json_t *in, pk_pack_job *job, pk_schema_errors *errs)
{
    size_t before = errs->n;
    memset(job, 0, sizeof *job);
    pk_options_fill(&pk_pack_options, in, job, errs);

    json_t *box = json_object_get(json_object_get(in, "domain"), "box");
    json_t *size = json_object_get(box, "size");
    job->mesh = json_object_get(json_object_get(in, "domain"), "mesh");
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
    job->discrete = job->sampling >= 0 ? job->sampling : default_discrete;

    const char *gtype = json_string_value(json_object_get(g, "type"));
    if (gtype && strcmp(gtype, "fuller") == 0) {
        double dmax = job->fuller_d_max, q = job->fuller_q;
        if (!(job->d_min > 0))
            pk_schema_errors_add(errs, "/d_min", "required",
                                 "a Fuller curve needs a cut-off diameter d_min");
        else if (job->d_min >= dmax)
            pk_schema_errors_add(errs, "/d_min", "lessThanDmax",
                                 "d_min (%g) must be below d_max (%g)", job->d_min, dmax);
        else if (pk_grading_from_fuller(&job->grading, q, dmax, job->d_min) != 0)
            pk_schema_errors_add(errs, "/grading", "grading", "%s", pk_psd_error());
    }

    job->has_phi = json_object_get(in, "phi") != NULL;
    auto_without_plan(in, job, box != NULL);
    const pk_placer *placer = pk_placer_find(job->algorithm);
    if (!placer)
        pk_schema_errors_add(errs, "/algorithm", "enum", "no placer named \"%s\"", job->algorithm);
    else if (!box && !placer->fills_mesh)
        pk_schema_errors_add(errs, "/domain", "boxDomain",
                             "algorithm \"%s\" needs a box domain (a mesh needs \"%s\")",
                             job->algorithm, pk_placer_filling_mesh()->name);
    if (placer && placer->options)
        pk_options_fill(placer->options, in, &job->opt, errs);
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
            own->check(job, plan, job->prepare ? &plan->prepared : NULL, errs);
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
        pk_schema_errors_add(
            errs, "/d_min", "maxParticles",
            "the grading above d_min = %g holds too many grains to count: raise d_min", job->d_min);
        return errs->n - before;
    }
    if (job->count) {
        plan->expected_n = (double)job->count;
        if (job->has_phi) /* Meier: absolute size set by the packing */
            plan->scale =
                pow(plan->phi_resolved * V / ((double)job->count * mean_measure), 1.0 / dim);
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
        const pk_placer *p = pk_placer_find(job->algorithm);
        const int jams = p && p->grows_until_jammed && p->grows_until_jammed(job);
        if (!(phi_shell < 1) && !jams) {
            const char *ptr = plan->phi_resolved < 1 && job->delta_d > 0 ? "/delta_d"
                : job->count && !job->has_phi                            ? "/count"
                                                                         : "/phi/value";
            pk_schema_errors_add(errs, ptr, "resolvedBelow1",
                                 "the grains would fill φ = %.4g of the box (%.4g with their gaps "
                                 "Δd): must be < 1",
                                 plan->phi_resolved, phi_shell);
        }
    }
    const pk_placer *placer = pk_placer_find(job->algorithm);
    if (placer && placer->check && errs->n == before)
        placer->check(job, plan, job->prepare ? &plan->prepared : NULL, errs);
    return errs->n - before;
}

void *pk_pack_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs)
{
    pk_pack_task *t = malloc(sizeof *t);
    if (!t) {
        pk_schema_errors_add(errs, "", "memory", "out of memory");
        return NULL;
    }
    if (pk_pack_job_from_json(inputs, &t->job, errs) == 0) {
        t->job.service = ctx->service;
        t->job.prepare = !ctx->service;
        if (pk_pack_plan_make(&t->job, &t->plan, errs) == 0 &&
            pk_pack_auto_resolve(inputs, &t->job, &t->plan, errs) == 0)
            return t;
        pk_pack_free(t);
        return NULL;
    }
    free(t);
    return NULL;
}

json_t *pk_pack_plan_json(const void *task)
{
    const pk_pack_plan *plan = &((const pk_pack_task *)task)->plan;
    return json_pack("{s:f,s:f,s:f,s:f,s:f,s:i}", "expected_grains", plan->expected_n,
                     "phi_target_mix", plan->phi_mix, "phi_target_resolved", plan->phi_resolved,
                     "mass_cut_fraction", plan->mass_cut, "d_max", plan->d_max, "size_classes",
                     plan->resolved.nclass);
}

void pk_pack_free(void *task)
{
    pk_pack_task *t = task;
    const pk_placer *placer = t ? pk_placer_find(t->job.algorithm) : NULL;
    if (placer && placer->release && t->plan.prepared)
        placer->release(t->plan.prepared);
    free(t);
}
