/* test_plot_data.c — the plots read a series from either layout a result
 * may use (flat `P/11` datasets or an H5MD element `P/value` [steps][d][d]),
 * unit attributes of fixed or variable length, and fit their axes. */
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api/picture/plot_axes.h"
#include "api/picture/plot_data.h"
#include "tests/check.h"

static void write_doubles(hid_t loc, const char *name, int rank, const hsize_t *dims,
                          const double *v)
{
    hid_t s = H5Screate_simple(rank, dims, NULL);
    hid_t d = H5Dcreate2(loc, name, H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
    H5Dclose(d);
    H5Sclose(s);
}

static void set_unit(hid_t f, const char *path, const char *unit, int variable)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT), t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, variable ? H5T_VARIABLE : strlen(unit));
    hid_t s = H5Screate(H5S_SCALAR), a = H5Acreate2(d, "unit", t, s, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, t, variable ? (const void *)&unit : (const void *)unit);
    H5Aclose(a);
    H5Sclose(s);
    H5Tclose(t);
    H5Dclose(d);
}

/* Three steps of a 2×2 tensor, P_ab(k) = 10a + b + 100k, in both layouts. */
static void test_both_layouts(void)
{
    char path[] = "/tmp/test_plot_data.XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    double full[12], comp[3];
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++)
                full[4 * k + 2 * a + b] = 10 * (a + 1) + (b + 1) + 100 * k;
    H5Gclose(H5Gcreate2(f, "flat", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Gclose(H5Gcreate2(f, "flat/P", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Gclose(H5Gcreate2(f, "h5md", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    H5Gclose(H5Gcreate2(f, "h5md/P", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    hsize_t one = 3, three[3] = {3, 2, 2};
    for (int c = 0; c < 4; c++) {
        char name[32];
        snprintf(name, sizeof name, "flat/P/%d%d", c / 2 + 1, c % 2 + 1);
        for (int k = 0; k < 3; k++)
            comp[k] = full[4 * k + c];
        write_doubles(f, name, 1, &one, comp);
    }
    write_doubles(f, "h5md/P/value", 3, three, full);
    set_unit(f, "flat/P/11", "N/mm", 0);
    set_unit(f, "h5md/P/value", "N/mm", 1);
    H5Fclose(f);

    f = pk_plot_file_open(path);
    CHECK(f >= 0);
    const char *roots[] = {"/flat/P", "/h5md/P"};
    for (int r = 0; r < 2; r++) {
        size_t n = 0;
        double *v = pk_plot_tensor(f, roots[r], 1, 0, &n);
        CHECK_MSG(v && n == 3, "%s", roots[r]);
        for (size_t k = 0; v && k < n; k++)
            CHECK_NEAR(v[k], 21 + 100.0 * k, 0);
        free(v);
        char unit[16], at[64];
        snprintf(at, sizeof at, "%s%s", roots[r], r ? "" : "/11");
        pk_plot_unit(f, at, unit, sizeof unit);
        CHECK_MSG(!strcmp(unit, "N/mm"), "%s: '%s'", at, unit);
    }
    size_t n = 7;
    CHECK(pk_plot_tensor(f, "/flat/P", 2, 2, &n) == NULL); /* a 2D tensor has no 33 */
    CHECK(pk_plot_tensor(f, "/h5md/P", 2, 2, &n) == NULL);
    CHECK(pk_plot_series(f, "/h5md/P", &n) == NULL && n == 0); /* rank 3 is not a series */
    CHECK(pk_plot_series(f, "/no/such/series", &n) == NULL);
    CHECK(isnan(pk_plot_scalar(f, "/nothing")));
    pk_plot_file_close(f);
    unlink(path);
}

static void test_axes(void)
{
    pk_plot_axis a = {0};
    pk_plot_axis_fit(&a, 0, 280010, 0); /* events: 0 .. 3e5 labelled in thousands */
    CHECK_NEAR(a.lo, 0, 0);
    CHECK_NEAR(a.hi, 300000, 1e-6);
    CHECK(a.exp10 == 3 && !a.log);
    pk_plot_axis_fit(&a, 5.2e-9, 167, 1); /* log: to the 1-2-5 values around */
    CHECK_NEAR(a.lo, 5e-9, 1e-20);
    CHECK_NEAR(a.hi, 200, 1e-9);
    double v[] = {NAN, -1, 0, 3, 1.79e308, 7};
    double lo, hi;
    CHECK(pk_plot_range(v, 6, 1, &lo, &hi) && lo == 3 && hi == 7); /* ±1.8e308: non-finite */
    CHECK(pk_plot_range(v, 6, 0, &lo, &hi) && lo == -1 && hi == 7);
    CHECK(!pk_plot_range(v, 3, 1, &lo, &hi));
    pk_plot p = {.left = 10, .top = 0, .right = 110, .bottom = 100};
    pk_plot_axis_fit(&p.x, 0, 10, 0);
    pk_plot_axis_fit(&p.y, 1, 100, 1);
    CHECK_NEAR(pk_plot_px(&p, 5), 60, 1e-9);
    CHECK_NEAR(pk_plot_py(&p, 10), 50, 1e-9);
    a = (pk_plot_axis){.integer = 1};
    pk_plot_axis_fit(&a, 1, 3, 0); /* load steps: whole numbers kept */
    CHECK(a.integer && a.lo == 1 && a.hi == 3);
}

int main(void)
{
    RUN(test_both_layouts);
    RUN(test_axes);
    return check_summary();
}
