/* test_pack_observables.c — the pack summary and the result file come from
 * one observable list (api/results/h5_observables.h): every field of a real
 * run's summary has its twin under /observables (the placer's under
 * /observables/<algorithm>/), every scalar field is a row of the list with its
 * unit kind, and a row with a unit has the unit attribute in the file. */
#include <hdf5.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "api/pack/pack_job.h"
#include "api/process.h"
#include "api/results/h5_observables.h"
#include "check.h"

/* The summary's members that are not observables of their own: the process
 * (/parameters), the verdict (/observables/verdict/) and the per-class table
 * (the grading/class_* columns). */
static const char *const envelope[] = {"process", "complete",      "warnings", "failure",
                                       "classes", "result_digest", NULL};

static int in(const char *const *list, const char *s)
{
    for (; *list; list++)
        if (!strcmp(*list, s))
            return 1;
    return 0;
}

static int exists(hid_t f, const char *path)
{
    char prefix[512];
    for (const char *s = strchr(path + 1, '/');; s = strchr(s + 1, '/')) {
        size_t n = s ? (size_t)(s - path) : strlen(path);
        snprintf(prefix, sizeof prefix, "%.*s", (int)n, path);
        if (H5Lexists(f, prefix, H5P_DEFAULT) <= 0)
            return 0;
        if (!s)
            return 1;
    }
}

/* Every leaf of v (objects walked) at path has a dataset or group there. */
static void twins(hid_t f, const char *path, json_t *v)
{
    if (json_is_object(v)) {
        const char *k;
        json_t *m;
        json_object_foreach (v, k, m) {
            char sub[512];
            snprintf(sub, sizeof sub, "%s/%s", path, k);
            twins(f, sub, m);
        }
        return;
    }
    /* a history's clock, {events, time}, is every series' H5MD step and time
     * (pk_h5_obs_history): history/<series>/step, history/<series>/time */
    char clock[600];
    const char *h = strstr(path, "/history/");
    if (h && (!strcmp(h, "/history/events") || !strcmp(h, "/history/time"))) {
        snprintf(clock, sizeof clock, "%.*s/history/phi/%s", (int)(h - path), path,
                 !strcmp(h, "/history/events") ? "step" : "time");
        path = clock;
    }
    CHECK_MSG(exists(f, path), "summary field %s has no dataset in the file", path);
}

static void check_run(const char *inputs)
{
    char dir[] = "/tmp/pk_obs_XXXXXX", out[300], job_text[1200], err[256] = "";
    CHECK(mkdtemp(dir) != NULL);
    snprintf(out, sizeof out, "%s/r.h5", dir);
    snprintf(job_text, sizeof job_text, "{\"process\": \"pack\", \"inputs\": %s}", inputs);
    json_t *job = json_loads(job_text, 0, NULL), *sum = NULL;
    pk_schema_errors errs = {0};
    int rc = pk_job_run(job, NULL, out, &sum, &errs, err, sizeof err);
    CHECK_MSG(rc == 0 && sum, "run: %d %s %s", rc, err, errs.n ? errs.items[0].message : "");
    hid_t f = sum ? H5Fopen(out, H5F_ACC_RDONLY, H5P_DEFAULT) : -1;
    const char *alg = json_string_value(json_object_get(sum, "algorithm"));
    const char *k;
    json_t *v;
    json_object_foreach (sum, k, v) {
        if (f < 0 || in(envelope, k))
            continue;
        char path[300];
        /* the summary's "model" is /observables/modelled */
        snprintf(path, sizeof path, "/observables/%s", !strcmp(k, "model") ? "modelled" : k);
        twins(f, path, v);
        if (!strcmp(k, "model") || !strcmp(k, "auto") || (alg && !strcmp(k, alg)))
            continue; /* records of their own: written whole */
        /* scalar observables (one level of groups, "timing/place_s"): rows
         * of the list, their units in the file */
        json_t *one = json_pack("{s:O}", k, v);
        const char *gk, *sk;
        json_t *gv, *sv;
        json_object_foreach (one, gk, gv) {
            json_t *leaves = json_is_object(gv) ? gv : one;
            json_object_foreach (leaves, sk, sv) {
                char name[300], ds[400];
                snprintf(name, sizeof name, "%s%s%s", leaves == one ? "" : gk,
                         leaves == one ? "" : "/", sk);
                const pk_unit_row *row = pk_obs_row(pk_pack_observables(), name);
                CHECK_MSG(row != NULL, "summary field %s is not in the observable list", name);
                snprintf(ds, sizeof ds, "/observables/%s", name);
                if (row && row->kind != PK_U_NONE)
                    CHECK_MSG(H5Aexists_by_name(f, ds, "unit", H5P_DEFAULT) > 0, "%s has no unit",
                              ds);
            }
        }
        json_decref(one);
    }
    if (f >= 0)
        H5Fclose(f);
    pk_schema_errors_free(&errs);
    json_decref(sum);
    json_decref(job);
    unlink(out);
    rmdir(dir);
}

/* Every row of the list is written (pk_h5_obs_rows refuses a missing value)
 * and is a summary field: the two hold the same names. */
static void test_rsa_walled(void)
{
    check_run("{\"dim\": 2, \"unit\": \"mm\", \"domain\": {\"box\": {\"size\": [12, 12], "
              "\"periodic\": false}}, \"grading\": {\"type\": \"fuller\", \"q\": 0.5, "
              "\"d_max\": 2}, \"d_min\": 0.5, \"delta_d\": 0.05, \"phi\": {\"value\": 0.3, "
              "\"refers_to\": \"resolved\"}, \"algorithm\": \"auto\"}");
}

static void test_edmd_periodic(void)
{
    check_run("{\"dim\": 2, \"unit\": \"mm\", \"domain\": {\"box\": {\"size\": [8, 8], "
              "\"periodic\": true}}, \"grading\": {\"type\": \"fuller\", \"q\": 0.5, "
              "\"d_max\": 2}, \"d_min\": 0.5, \"phi\": {\"value\": 0.5, "
              "\"refers_to\": \"resolved\"}, \"algorithm\": \"edmd\", \"quality\": \"draft\"}");
}

static void test_rows_are_summary_fields(void)
{
    /* a value missing for a row is an error, not a silent gap */
    json_t *o = json_object();
    pk_obs_set(o, "timing/place_s", json_real(1));
    CHECK(json_number_value(pk_obs_value(o, "timing/place_s")) == 1);
    CHECK(pk_obs_value(o, "timing/none") == NULL && pk_obs_value(o, "x/y") == NULL);
    CHECK(pk_obs_set(o, "timing/place_s/x", json_real(2)) == -1); /* through a number */
    json_decref(o);
}

int main(void)
{
    RUN(test_rows_are_summary_fields);
    RUN(test_rsa_walled);
    RUN(test_edmd_periodic);
    return check_summary();
}
