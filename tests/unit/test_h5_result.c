/* test_h5_result.c — result files read back with the HDF5 library itself:
 * the H5MD layout, exact round trip of the grains, atomic commit/abort. */
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/results/h5_inspect.h"
#include "api/results/h5_result.h"
#include "api/results/h5_units.h"

static char dir[] = "/tmp/packd-h5-XXXXXX";

static void fill(pk_particles *p, int dim, size_t n)
{
    pk_particles_init(p, dim, n);
    for (size_t i = 0; i < n; i++) {
        double x[3] = {0.1 * (double)i, 1.0 / (double)(i + 1), dim == 3 ? 3.0 + (double)i : 0};
        pk_particles_push(p, x, 0.01 + 1e-3 * (double)i, (int32_t)(i % 3));
    }
}

static int exists(const char *path) { return access(path, F_OK) == 0; }

static void test_round_trip_and_layout(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/a.h5", dir);
    pk_box b = {.dim = 3, .L = {1, 2, 3}, .periodic = {true, false, true}};
    pk_particles p;
    fill(&p, 3, 100);
    char err[256];
    pk_h5 *h = pk_h5_create(path, NULL, err, sizeof err);
    CHECK(h != NULL);
    CHECK(!exists(path)); /* nothing at the final name before commit */
    CHECK(pk_h5_write_particles(h, &b, &p, "mm") == 0);
    CHECK(pk_h5_write_parameters(h, "pack", "{\"process\":\"pack\"}", 42) == 0);
    CHECK(pk_h5_obs_double(h, "phi_resolved", 0.5, NULL) == 0);
    CHECK(pk_h5_obs_string(h, "termination_reason", "complete") == 0);
    json_t *extra =
        json_pack("{s:i,s:[f,f],s:{s:s}}", "events", 7, "hist", 0.1, 0.2, "sub", "k", "v");
    CHECK(pk_h5_obs_json(h, "edmd", extra) == 0);
    json_decref(extra);
    CHECK(pk_h5_commit(h, err, sizeof err) == 0);
    CHECK(exists(path));

    /* grains: exact round trip through pk_h5_read_particles */
    pk_box b2;
    pk_particles q;
    CHECK(pk_h5_read_particles(path, &b2, &q, err, sizeof err) == 0);
    CHECK(b2.dim == 3 && q.n == p.n);
    CHECK(memcmp(b2.L, b.L, sizeof b.L) == 0);
    CHECK(b2.periodic[0] && !b2.periodic[1] && b2.periodic[2]);
    CHECK(memcmp(q.x, p.x, 3 * p.n * sizeof(double)) == 0);
    CHECK(memcmp(q.r, p.r, p.n * sizeof(double)) == 0);
    CHECK(memcmp(q.species, p.species, p.n * sizeof(int32_t)) == 0);
    pk_particles_free(&q);

    /* H5MD layout, read with the HDF5 library directly */
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK(f >= 0);
    int ver[2] = {0, 0};
    hid_t a = H5Aopen_by_name(f, "h5md", "version", H5P_DEFAULT, H5P_DEFAULT);
    CHECK(a >= 0 && H5Aread(a, H5T_NATIVE_INT, ver) >= 0);
    H5Aclose(a);
    CHECK(ver[0] == 1 && ver[1] == 1);
    CHECK(H5Lexists(f, "h5md/creator", H5P_DEFAULT) > 0);
    hid_t d = H5Dopen2(f, "particles/grains/position", H5P_DEFAULT);
    hid_t s = H5Dget_space(d);
    hsize_t dims[2];
    CHECK(H5Sget_simple_extent_ndims(s) == 2);
    H5Sget_simple_extent_dims(s, dims, NULL);
    CHECK(dims[0] == 100 && dims[1] == 3);
    CHECK(H5Aexists(d, "unit") > 0);
    H5Sclose(s);
    H5Dclose(d);
    CHECK(H5Lexists(f, "observables/edmd", H5P_DEFAULT) > 0);
    CHECK(H5Lexists(f, "observables/edmd/sub", H5P_DEFAULT) > 0);
    CHECK(H5Lexists(f, "parameters/job", H5P_DEFAULT) > 0);
    H5Fclose(f);

    /* the JSON view */
    json_t *j = pk_h5_inspect(path, 64, err, sizeof err);
    CHECK(j != NULL);
    json_t *o = json_object_get(j, "observables");
    CHECK(json_integer_value(json_object_get(o, "edmd/events")) == 7);
    CHECK(json_array_size(json_object_get(o, "edmd/hist")) == 2);
    CHECK(strcmp(json_string_value(json_object_get(o, "termination_reason")), "complete") == 0);
    CHECK(json_integer_value(json_object_get(j, "grains")) == 100);
    json_decref(j);
    pk_particles_free(&p);
    unlink(path);
}

static void test_2d_positions_have_two_columns(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/b.h5", dir);
    pk_box b = {.dim = 2, .L = {5, 5}, .periodic = {true, true}};
    pk_particles p;
    fill(&p, 2, 10);
    char err[256];
    pk_h5 *h = pk_h5_create(path, NULL, err, sizeof err);
    pk_h5_write_particles(h, &b, &p, "mm");
    CHECK(pk_h5_commit(h, err, sizeof err) == 0);
    pk_box b2;
    pk_particles q;
    CHECK(pk_h5_read_particles(path, &b2, &q, err, sizeof err) == 0);
    CHECK(b2.dim == 2 && q.n == 10 && q.x[3 * 5 + 2] == 0.0);
    CHECK(q.x[3 * 5 + 1] == p.x[3 * 5 + 1]);
    pk_particles_free(&p);
    pk_particles_free(&q);
    unlink(path);
}

/* abort leaves nothing behind; an existing file is only replaced on commit */
static void test_abort_and_atomic_replace(void)
{
    char path[256], tmp[300];
    snprintf(path, sizeof path, "%s/c.h5", dir);
    FILE *old = fopen(path, "w");
    fputs("old content", old);
    fclose(old);
    char err[256];
    pk_h5 *h = pk_h5_create(path, NULL, err, sizeof err);
    CHECK(h != NULL);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    CHECK(exists(tmp));
    pk_h5_abort(h);
    CHECK(!exists(tmp));
    FILE *f = fopen(path, "r");
    char buf[32] = "";
    CHECK(f && fgets(buf, sizeof buf, f) && strcmp(buf, "old content") == 0);
    if (f)
        fclose(f);
    /* a failing create reports an error instead of crashing */
    CHECK(pk_h5_create("/nonexistent-dir/x.h5", NULL, err, sizeof err) == NULL);
    CHECK(strlen(err) > 0);
    unlink(path);
}

/* A link names the box; a failed write is sticky: the file is refused at
 * commit and none is left. */
static void test_link_and_sticky_failure(void)
{
    char path[256], err[256];
    snprintf(path, sizeof path, "%s/v.h5", dir);
    pk_box b = {.dim = 2, .L = {1, 1}, .periodic = {true, true}};
    pk_particles p;
    fill(&p, 2, 4);
    double v[3 * 4 * 2];
    for (size_t i = 0; i < 24; i++)
        v[i] = (double)i;
    pk_h5 *h = pk_h5_create(path, NULL, err, sizeof err);
    CHECK(h != NULL);
    CHECK(pk_h5_write_particles(h, &b, &p, "mm") == 0);
    size_t d[6] = {3, 4, 2, 1, 1, 1};
    CHECK(pk_h5_write_array(h, "/particles/x/position/value", PK_H5_F64, 3, d, v, "mm") == 0);
    CHECK(pk_h5_link(h, "/particles/grains/box", "/particles/x/box") == 0);
    CHECK(!pk_h5_failed(h));
    CHECK(pk_h5_commit(h, err, sizeof err) == 0);

    char bad[300];
    snprintf(bad, sizeof bad, "%s/bad.h5", dir);
    pk_h5 *h2 = pk_h5_create(bad, NULL, err, sizeof err);
    pk_h5_write_array(h2, "/particles/x/position/value", PK_H5_F64, 3, d, v, "mm");
    CHECK(pk_h5_write_array(h2, "/particles/x/six", PK_H5_F64, 6, d, v, NULL) != 0);
    CHECK(pk_h5_failed(h2));
    pk_h5_obs_double(h2, "after", 1, NULL); /* writes on, still refused */
    CHECK(pk_h5_commit(h2, err, sizeof err) != 0 && strstr(err, "writing") != NULL);
    CHECK(access(bad, F_OK) != 0);
    pk_particles_free(&p);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK(H5Lexists(f, "/particles/x/box/edges", H5P_DEFAULT) > 0);
    H5Fclose(f);
    unlink(path);
}

/* The unit attribute of path: scalar, ASCII, its text in out. */
static int unit_of(hid_t f, const char *path, char *out, size_t n)
{
    hid_t d = H5Oopen(f, path, H5P_DEFAULT);
    hid_t a = d >= 0 && H5Aexists(d, "unit") > 0 ? H5Aopen(d, "unit", H5P_DEFAULT) : -1;
    hid_t t = a >= 0 ? H5Aget_type(a) : -1, sp = a >= 0 ? H5Aget_space(a) : -1;
    int ok = t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tget_cset(t) == H5T_CSET_ASCII &&
        H5Sget_simple_extent_type(sp) == H5S_SCALAR && H5Tget_size(t) <= n &&
        H5Aread(a, t, out) >= 0;
    if (sp >= 0)
        H5Sclose(sp);
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
    if (d >= 0)
        H5Oclose(d);
    return ok ? 0 : -1;
}

/* H5MD elements: step/time/value, shared step and time, units module and
 * unit strings, connectivity with its particles group, the author. */
static void test_h5md_elements_units_author(void)
{
    pk_units u3, u2, none;
    pk_units_init(&u3, "mm", 3);
    pk_units_init(&u2, "mm", 2);
    pk_units_init(&none, "1", 2);
    CHECK(!strcmp(u3.stress, "N mm-2") && !strcmp(u2.stress, "N mm-1"));
    CHECK(!strcmp(u3.volume, "mm+3") && !strcmp(u2.energy, "N mm"));
    static const pk_unit_row rows[] = {{"E_n", PK_U_STIFFNESS}, {"d", PK_U_LENGTH}, {NULL}};
    CHECK(!strcmp(pk_unit_in(rows, "E_n", &u2), "N mm-1"));
    CHECK(!strcmp(pk_unit_in(rows, "d", &u3), "mm"));
    CHECK(pk_unit_in(rows, "E_n", &none) == NULL); /* no length unit: none */
    CHECK(pk_unit_in(rows, "J", &u3) == NULL);

    char path[256], err[256], buf[64];
    snprintf(path, sizeof path, "%s/e.h5", dir);
    pk_box b = {.dim = 2, .L = {1, 1}, .periodic = {true, true}};
    pk_particles p;
    fill(&p, 2, 3);
    pk_h5 *h = pk_h5_create(path, "dora", err, sizeof err);
    CHECK(h != NULL);
    CHECK(pk_h5_write_particles(h, &b, &p, "mm") == 0);
    int64_t step[2] = {0, 1};
    double time[2] = {0.5, 1}, P[8] = {1, 2, 3, 4, 5, 6, 7, 8}, J[2] = {1, 0.99};
    size_t dP[3] = {2, 2, 2}, dJ[1] = {2};
    CHECK(pk_h5_time_element(h, "/observables/x/P", NULL, step, time, NULL, PK_H5_F64, 3, dP, P,
                             u2.stress) == 0);
    CHECK(pk_h5_time_element(h, "/observables/x/J", "/observables/x/P", NULL, NULL, NULL, PK_H5_F64,
                             1, dJ, J, NULL) == 0);
    int64_t pairs[4] = {0, 1, 1, 2};
    CHECK(pk_h5_connectivity(h, "/connectivity/contacts", pairs, 2, "/particles/grains") == 0);
    CHECK(pk_h5_commit(h, err, sizeof err) == 0);
    pk_particles_free(&p);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK(unit_of(f, "/observables/x/P/value", buf, sizeof buf) == 0 && !strcmp(buf, "N mm-1"));
    CHECK(unit_of(f, "/particles/grains/position", buf, sizeof buf) == 0 && !strcmp(buf, "mm"));
    H5O_info_t a, c; /* J's step is P's step: one object */
    CHECK(H5Oget_info_by_name(f, "/observables/x/J/step", &a, H5P_DEFAULT) >= 0);
    CHECK(H5Oget_info_by_name(f, "/observables/x/P/step", &c, H5P_DEFAULT) >= 0);
    CHECK(a.addr == c.addr);
    CHECK(H5Aexists_by_name(f, "/h5md/modules/units", "system", H5P_DEFAULT) > 0);
    CHECK(H5Aexists_by_name(f, "/connectivity/contacts", "particles_group", H5P_DEFAULT) > 0);
    hid_t au = H5Aopen_by_name(f, "/h5md/author", "name", H5P_DEFAULT, H5P_DEFAULT);
    hid_t at = H5Aget_type(au);
    memset(buf, 0, sizeof buf);
    CHECK(H5Tget_size(at) < sizeof buf && H5Aread(au, at, buf) >= 0 && !strcmp(buf, "dora"));
    H5Tclose(at);
    H5Aclose(au);
    H5Fclose(f);
    unlink(path);
}

static void test_read_rejects_non_result(void)
{
    char path[256], err[256];
    snprintf(path, sizeof path, "%s/not.h5", dir);
    FILE *f = fopen(path, "w");
    fputs("this is not HDF5", f);
    fclose(f);
    pk_box b;
    pk_particles p;
    CHECK(pk_h5_read_particles(path, &b, &p, err, sizeof err) != 0);
    CHECK(strstr(err, "HDF5") != NULL);
    unlink(path);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    RUN(test_round_trip_and_layout);
    RUN(test_2d_positions_have_two_columns);
    RUN(test_abort_and_atomic_replace);
    RUN(test_link_and_sticky_failure);
    RUN(test_read_rejects_non_result);
    RUN(test_h5md_elements_units_author);
    rmdir(dir);
    return check_summary();
}
