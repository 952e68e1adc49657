/* test_observables.c — each process's summary and result file come from one
 * observable list (api/results/h5_observables.h, the process table's
 * `observables`): every process runs here, and every field of its summary
 * must be a row of its list, have its twin under /observables (the row's
 * file path; a PK_OBS_RUN row, how the job ran, is the summary's alone) and,
 * for a row with a unit, carry that unit in the file and in the summary's
 * "units".  A process added to the table without a job here
 * fails too. */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api/process.h"
#include "api/results/h5_observables.h"
#include "check.h"

/* The summary's members that are not observables of their own: the process
 * (/parameters), the verdict (/observables/verdict/), pack's per-class table
 * (the grading/class_* columns), the digest (/parameters/result_digest) and
 * the units themselves. */
static const char *const envelope[] = {"process", "complete",      "warnings", "failure",
                                       "classes", "result_digest", "units",    NULL};

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

/* A placer's record (pack's /observables/<algorithm>/, the placer's units):
 * every leaf of v at path has a dataset or group there. */
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

/* The unit attribute of the dataset at path (an H5MD element: its value),
 * into unit; 0 when there is none. */
static int unit_in_file(hid_t f, const char *path, char *unit, size_t n)
{
    char p[600];
    snprintf(p, sizeof p, "%s/value", path);
    if (!exists(f, p))
        snprintf(p, sizeof p, "%s", path);
    if (H5Aexists_by_name(f, p, "unit", H5P_DEFAULT) <= 0)
        return 0;
    hid_t a = H5Aopen_by_name(f, p, "unit", H5P_DEFAULT, H5P_DEFAULT);
    hid_t t = H5Aget_type(a), mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, n);
    memset(unit, 0, n);
    int ok = H5Tis_variable_str(t) <= 0 && H5Aread(a, mt, unit) >= 0;
    H5Tclose(mt);
    H5Tclose(t);
    H5Aclose(a);
    return ok;
}

/* Summary member name (value v) of process p: a row, or an object whose
 * members are. */
static void check_field(hid_t f, const pk_process *p, json_t *units, const char *name, json_t *v)
{
    const pk_obs_row *row = pk_obs_row_named(p->observables, name);
    if (!row && json_is_object(v)) {
        const char *k;
        json_t *m;
        json_object_foreach (v, k, m) {
            char sub[300];
            snprintf(sub, sizeof sub, "%s/%s", name, k);
            check_field(f, p, units, sub, m);
        }
        return;
    }
    CHECK_MSG(row != NULL, "%s: summary field %s is not in the observable list", p->id, name);
    if (!row)
        return;
    char path[400], unit[64];
    const char *said = json_string_value(json_object_get(units, name));
    if (row->form == PK_OBS_RUN) { /* how it ran: the summary's alone, its unit there */
        CHECK_MSG((row->kind == PK_U_NONE) == !said, "%s: %s's unit in the summary: %s", p->id,
                  name, said ? said : "(none)");
        return;
    }
    snprintf(path, sizeof path, "/observables/%s", pk_obs_file(row));
    CHECK_MSG(exists(f, path), "%s: summary field %s has no twin %s in the file", p->id, name,
              path);
    if (row->kind == PK_U_NONE) {
        CHECK_MSG(!said, "%s: %s is a number without unit, the summary says %s", p->id, name, said);
        return;
    }
    int has = unit_in_file(f, path, unit, sizeof unit);
    CHECK_MSG(has, "%s: %s has no unit", p->id, path);
    CHECK_MSG(said && has && !strcmp(said, unit),
              "%s: the summary's unit of %s is %s, the file's %s", p->id, name,
              said ? said : "(none)", has ? unit : "(none)");
}

/* Run the job of process id (inputs) into dir/out; check its summary. */
static void check_run(const char *id, const char *inputs, const char *dir, const char *out)
{
    char path[300], job_text[3000], err[256] = "";
    snprintf(path, sizeof path, "%s/%s", dir, out);
    snprintf(job_text, sizeof job_text, "{\"process\": \"%s\", \"inputs\": %s}", id, inputs);
    json_error_t jerr;
    json_t *job = json_loads(job_text, 0, &jerr), *sum = NULL;
    CHECK_MSG(job != NULL, "%s job: %s", id, jerr.text);
    pk_schema_errors errs = {0};
    int rc = job ? pk_job_run(job, NULL, path, &sum, &errs, err, sizeof err) : -1;
    CHECK_MSG(rc == 0 && sum, "%s run: %d %s %s", id, rc, err, errs.n ? errs.items[0].message : "");
    const pk_process *p = pk_process_find(id);
    hid_t f = sum ? H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT) : -1;
    const char *alg = json_string_value(json_object_get(sum, "algorithm"));
    json_t *units = json_object_get(sum, "units");
    CHECK_MSG(json_is_object(units), "%s: the summary has no units", id);
    const char *k;
    json_t *v;
    json_object_foreach (sum, k, v) {
        if (f < 0 || in(envelope, k))
            continue;
        if (!strcmp(id, "pack") && alg && !strcmp(k, alg)) {
            char gp[300];
            snprintf(gp, sizeof gp, "/observables/%s", k);
            twins(f, gp, v); /* the placer's record, written whole */
        } else
            check_field(f, p, units, k, v);
    }
    /* every unit the summary states is a field's */
    json_object_foreach (units, k, v)
        CHECK_MSG(pk_obs_value(sum, k) != NULL, "%s: a unit for %s, no such field", id, k);
    if (f >= 0)
        H5Fclose(f);
    pk_schema_errors_free(&errs);
    json_decref(sum);
    json_decref(job);
}

#define RVE_2D                                                                                     \
    "{\"dim\": 2, \"unit\": \"mm\", \"domain\": {\"box\": {\"size\": [8, 8], \"periodic\": "       \
    "true}}, \"grading\": {\"type\": \"classes\", \"classes\": [{\"d\": 2.0, "                     \
    "\"volume_percent\": 0}, {\"d\": 1.6, \"volume_percent\": 60}, {\"d\": 1.2, "                  \
    "\"volume_percent\": 40}]}, \"sampling\": \"discrete\", \"count\": 24, \"phi\": {\"value\": "  \
    "0.5, \"refers_to\": \"resolved\"}, \"algorithm\": \"rsa\", \"seed\": 1}"

/* One run of each process, and more where a run's fields depend on its
 * options (walls, a placer's record; friction, the hull, the tangent). */
static void test_every_process(void)
{
    char dir[] = "/tmp/pk_obs_XXXXXX", inputs[2000];
    CHECK(mkdtemp(dir) != NULL);
    const char *ran[8];
    size_t nran = 0;
    check_run("pack",
              "{\"dim\": 2, \"unit\": \"mm\", \"domain\": {\"box\": {\"size\": [12, 12], "
              "\"periodic\": false}}, \"grading\": {\"type\": \"fuller\", \"q\": 0.5, "
              "\"d_max\": 2}, \"d_min\": 0.5, \"delta_d\": 0.05, \"phi\": {\"value\": 0.3, "
              "\"refers_to\": \"resolved\"}, \"algorithm\": \"auto\"}",
              dir, "walled.h5");
    check_run("pack",
              "{\"dim\": 2, \"unit\": \"mm\", \"domain\": {\"box\": {\"size\": [8, 8], "
              "\"periodic\": true}}, \"grading\": {\"type\": \"fuller\", \"q\": 0.5, "
              "\"d_max\": 2}, \"d_min\": 0.5, \"phi\": {\"value\": 0.5, "
              "\"refers_to\": \"resolved\"}, \"algorithm\": \"edmd\", \"quality\": \"draft\"}",
              dir, "edmd.h5");
    check_run("pack", RVE_2D, dir, "rve.h5");
    ran[nran++] = "pack";
    snprintf(inputs, sizeof inputs,
             "{\"rve\": {\"file\": \"%s/rve.h5\"}, \"boundary_condition\": \"periodic\", "
             "\"load\": {\"type\": \"uniaxial_compression\", \"axis\": 1, \"strain\": 0.01, "
             "\"steps\": 2}, \"contact\": {\"E_n\": 50}, \"initial_state\": {\"policy\": "
             "\"radius_inflation\", \"value\": 0.3}, \"tangent\": true, \"output\": "
             "{\"micro_state\": true, \"contacts\": true}}",
             dir);
    check_run("homogenize", inputs, dir, "periodic.h5");
    snprintf(inputs, sizeof inputs,
             "{\"rve\": {\"file\": \"%s/rve.h5\"}, \"boundary_condition\": \"taylor\", "
             "\"load\": {\"type\": \"uniaxial_compression\", \"axis\": 1, \"strain\": 0.01, "
             "\"steps\": 2}, \"contact\": {\"E_n\": 50}, \"friction\": {\"rho_deg\": 30, "
             "\"E_t\": 50, \"h\": 50}, \"initial_state\": {\"policy\": \"radius_inflation\", "
             "\"value\": 0.3}}",
             dir);
    check_run("homogenize", inputs, dir, "friction.h5");
    snprintf(inputs, sizeof inputs,
             "{\"rve\": {\"file\": \"%s/rve.h5\"}, \"boundary_condition\": "
             "\"restricted_taylor\", \"load\": {\"type\": \"uniaxial_compression\", \"axis\": 1, "
             "\"strain\": 0.01, \"steps\": 2}, \"contact\": {\"E_n\": 50}, "
             "\"initial_state\": {\"policy\": \"radius_inflation\", \"value\": 0.3}}",
             dir);
    check_run("homogenize", inputs, dir, "hull.h5");
    ran[nran++] = "homogenize";
    snprintf(inputs, sizeof inputs,
             "{\"unit\": \"mm\", \"mesh\": {\"rectangle\": {\"size\": [10, 10], \"elements\": "
             "[1, 1]}}, \"boundary_conditions\": [{\"name\": \"bottom\", \"type\": "
             "\"displacement\", \"on\": \"bottom\", \"component\": \"y\"}, {\"name\": \"left\", "
             "\"type\": \"displacement\", \"on\": \"left\", \"component\": \"x\"}, {\"name\": "
             "\"top\", \"type\": \"displacement\", \"on\": \"top\", \"component\": \"y\"}], "
             "\"initial_stress\": \"balanced\", \"stages\": [{\"increments\": 2, \"targets\": "
             "{\"top\": -0.01}}], \"micro\": "
             "{\"rve\": {\"file\": \"%s/rve.h5\"}, \"boundary_condition\": \"taylor\", "
             "\"contact\": {\"E_n\": 50}, \"initial_state\": {\"policy\": "
             "\"radius_inflation\", \"value\": 0.3}}}",
             dir);
    check_run("fe2", inputs, dir, "fe2.h5");
    ran[nran++] = "fe2";
    ran[nran] = NULL;
    for (size_t i = 0; pk_processes[i]; i++) {
        CHECK_MSG(pk_processes[i]->observables != NULL, "%s has no observable list",
                  pk_processes[i]->id);
        CHECK_MSG(in(ran, pk_processes[i]->id), "%s has no run in this test", pk_processes[i]->id);
    }
    const char *names[] = {"walled.h5",   "edmd.h5", "rve.h5", "periodic.h5",
                           "friction.h5", "hull.h5", "fe2.h5"};
    char path[300];
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    CHECK_MSG(rmdir(dir) == 0, "files left in %s", dir);
}

static void test_values(void)
{
    json_t *o = json_object();
    pk_obs_set(o, "timing/place_s", json_real(1));
    CHECK(json_number_value(pk_obs_value(o, "timing/place_s")) == 1);
    CHECK(pk_obs_value(o, "timing/none") == NULL && pk_obs_value(o, "x/y") == NULL);
    CHECK(pk_obs_set(o, "timing/place_s/x", json_real(2)) == -1); /* through a number */
    json_decref(o);
}

/* The lookups: a summary member by name (file-only rows are none), a unit
 * by the file path, the summary's units for the members it holds. */
static void test_rows(void)
{
    static const pk_obs_row rows[] = {
        {"d", PK_U_LENGTH, PK_OBS_SCALAR, "g/d"},
        {"n", PK_U_NONE, PK_OBS_SCALAR, NULL},
        {"g/series", PK_U_STRESS, PK_OBS_FILE, NULL},
        {NULL, PK_U_NONE, PK_OBS_SCALAR, NULL},
    };
    pk_units u;
    pk_units_init(&u, "mm", 2);
    CHECK(pk_obs_row_named(rows, "d") == &rows[0] && pk_obs_row_named(rows, "g/series") == NULL);
    CHECK(!strcmp(pk_obs_unit_at(rows, "g/d", &u), "mm") && !pk_obs_unit_at(rows, "d", &u));
    CHECK(!strcmp(pk_obs_unit_at(rows, "g/series", &u), "N mm-1"));
    json_t *sum = json_pack("{s:f,s:i}", "d", 1.0, "n", 3);
    json_t *units = pk_obs_units_json(rows, sum, &u);
    CHECK(json_object_size(units) == 1 &&
          !strcmp(json_string_value(json_object_get(units, "d")), "mm"));
    json_decref(units);
    json_decref(sum);
}

int main(void)
{
    RUN(test_values);
    RUN(test_rows);
    RUN(test_every_process);
    return check_summary();
}
