/* test_job_verdict.c — the verdict contract (api/job_verdict.h): warnings
 * accumulate, the first failure wins and clears complete, and the file's
 * /observables/verdict/ group says the same, read back with HDF5 itself. */
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/job_verdict.h"

static char dir[] = "/tmp/packd-verdict-XXXXXX";

static void test_summary_members(void)
{
    json_t *s = json_pack("{s:b}", "complete", 1);
    CHECK(!pk_verdict_failed(s));
    CHECK(!strcmp(pk_verdict_status(s), "successful"));
    pk_verdict_warn(s, "phi %.2f reached of %.2f", 0.5, 0.6);
    pk_verdict_warn(s, "second");
    CHECK(json_array_size(json_object_get(s, "warnings")) == 2);
    CHECK(!strcmp(json_string_value(json_array_get(json_object_get(s, "warnings"), 0)),
                  "phi 0.50 reached of 0.60"));
    CHECK(json_is_true(json_object_get(s, "complete")));
    pk_verdict_fail(s, "wall time of %d s exceeded", 5);
    pk_verdict_fail(s, "a later reason");
    CHECK(pk_verdict_failed(s));
    CHECK(!strcmp(pk_verdict_status(s), "failed"));
    CHECK(json_is_false(json_object_get(s, "complete")));
    CHECK(!strcmp(json_string_value(json_object_get(s, "failure")), "wall time of 5 s exceeded"));
    json_decref(s);
}

static char *read_string(hid_t f, const char *name)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    if (d < 0)
        return NULL;
    hid_t t = H5Dget_type(d);
    char *out = NULL;
    if (H5Tis_variable_str(t) > 0) {
        char *v = NULL;
        hid_t mt = H5Tcopy(H5T_C_S1);
        H5Tset_size(mt, H5T_VARIABLE);
        if (H5Dread(d, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) >= 0 && v)
            out = strdup(v);
        H5free_memory(v);
        H5Tclose(mt);
    } else {
        size_t n = H5Tget_size(t);
        out = calloc(1, n + 1);
        H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, out);
    }
    H5Tclose(t);
    H5Dclose(d);
    return out;
}

static long long read_int(hid_t f, const char *name)
{
    long long v = -1;
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    if (d >= 0) {
        H5Dread(d, H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v);
        H5Dclose(d);
    }
    return v;
}

static void test_file_group(void)
{
    char path[256], err[256];
    snprintf(path, sizeof path, "%s/v.h5", dir);
    json_t *s = json_pack("{s:b}", "complete", 1);
    pk_verdict_warn(s, "one");
    pk_verdict_warn(s, "two");
    pk_verdict_fail(s, "diverged at step 3");
    pk_h5 *h = pk_h5_create(path, NULL, err, sizeof err);
    CHECK(h != NULL);
    CHECK(pk_verdict_write_h5(h, s) == 0);
    CHECK(pk_h5_commit(h, err, sizeof err) == 0);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK(f >= 0);
    char *st = read_string(f, "/observables/verdict/status");
    char *fail = read_string(f, "/observables/verdict/failure");
    char *warn = read_string(f, "/observables/verdict/warnings");
    CHECK(st && !strcmp(st, "failed"));
    CHECK(fail && !strcmp(fail, "diverged at step 3"));
    CHECK(warn && !strcmp(warn, "one\ntwo"));
    CHECK(read_int(f, "/observables/verdict/complete") == 0);
    CHECK(read_int(f, "/observables/verdict/warning_count") == 2);
    free(st);
    free(fail);
    free(warn);
    H5Fclose(f);
    unlink(path);
    json_decref(s);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    RUN(test_summary_members);
    RUN(test_file_group);
    rmdir(dir);
    return check_summary();
}
