/* test_input_files.c — input files are never trusted (issue 20): the
 * readers refuse FIFOs, devices and directories at once (an alarm turns the
 * old hang on /dev/zero or a FIFO into a failure), the service's checks
 * open no file, and server paths in a request are refused or confined to
 * the input directory (no "..", no symlink out, regular files, size cap). */
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "api/results/h5_result.h"
#include "api/inputs/input_confine.h"
#include "api/inputs/input_open.h"
#include "api/mesh/mesh_io.h"
#include "api/process.h"

static char dir[64];

static void on_alarm(int sig)
{
    (void)sig;
    static const char m[] = "FAIL a reader blocked on a special file\n";
    (void)!write(2, m, sizeof m - 1);
    _exit(1);
}

static void put(const char *name, const char *text)
{
    char p[256];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    fputs(text, f);
    fclose(f);
}

static const char *at(const char *name)
{
    static char p[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", dir, name);
    return p[k];
}

static void test_open_refuses_special_files(void)
{
    char err[256];
    alarm(10);
    CHECK(pk_input_open("/dev/zero", 0, err, sizeof err) < 0 && strstr(err, "character device"));
    CHECK(pk_input_open(at("fifo"), 0, err, sizeof err) < 0 && strstr(err, "FIFO"));
    CHECK(pk_input_open(dir, 0, err, sizeof err) < 0 && strstr(err, "directory"));
    CHECK(pk_input_open(at("missing"), 0, err, sizeof err) < 0);
    int fd = pk_input_open(at("small.txt"), 0, err, sizeof err);
    CHECK(fd >= 0);
    if (fd >= 0)
        close(fd);
    CHECK(pk_input_open(at("small.txt"), 3, err, sizeof err) < 0 &&
          strstr(err, "over the input limit"));
    alarm(0);
}

static void test_readers_refuse_special_files(void)
{
    const char *files[] = {"/dev/zero", at("fifo"), at("zero.msh"), at("fifo.msh")};
    char err[512];
    alarm(10);
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        json_t *j = json_pack("{s:s}", "file", files[i]);
        pk_mesh m;
        pk_mesh_report rep;
        CHECK_MSG(pk_mesh_from_json(j, 0, &m, &rep, err, sizeof err) != 0 &&
                      strstr(err, "not a regular file"),
                  "%s: %s", files[i], err);
        json_decref(j);
        pk_box b;
        pk_particles p;
        CHECK(pk_h5_read_particles(files[i], &b, &p, err, sizeof err) != 0 &&
              strstr(err, "not a regular file"));
    }
    /* a TetGen pair whose .ele is a FIFO */
    json_t *j = json_pack("{s:s}", "file", at("pair"));
    pk_mesh m;
    CHECK(pk_mesh_from_json(j, 0, &m, NULL, err, sizeof err) != 0 && strstr(err, "FIFO"));
    json_decref(j);
    alarm(0);
}

static json_t *tetfill(const char *file)
{
    return json_pack("{s:i,s:{s:{s:s}},s:s,s:{s:i},s:{s:f,s:s}}", "dim", 3, "domain", "mesh",
                     "file", file, "algorithm", "tetfill", "tetfill", "ratio", 3, "phi", "value",
                     0.3, "refers_to", "resolved");
}

static void test_service_checks_open_nothing(void)
{
    const pk_process *p = pk_process_find("pack");
    const pk_check_ctx service = {.service = 1}, local = {.service = 0};
    alarm(10);
    json_t *in = tetfill(at("fifo.msh"));
    pk_schema_errors errs = {0};
    CHECK(pk_process_validate_inputs(p, in, &service, &errs) == 0);
    pk_schema_errors_free(&errs);
    errs = (pk_schema_errors){0};
    CHECK(pk_process_validate_inputs(p, in, &local, &errs) == 1 &&
          strstr(errs.items[0].message, "FIFO") &&
          !strcmp(errs.items[0].pointer, "/domain/mesh/file"));
    pk_schema_errors_free(&errs);
    json_decref(in);
    /* a box domain is not meshed for a request, but its size limit still holds:
     * 0.1..0.5 radii in 82 x 40 x 20 take ~58 000 tets (fuzz_request timed out
     * meshing it in the check) */
    in = json_pack("{s:i,s:{s:{s:[i,i,i]}},s:s,s:{s:f,s:f,s:i}}", "dim", 3, "domain", "box", "size",
                   82, 40, 20, "algorithm", "tetfill", "tetfill", "r_min", 0.1, "r_max", 0.5,
                   "max_tets", 50000);
    errs = (pk_schema_errors){0};
    CHECK(pk_process_validate_inputs(p, in, &service, &errs) == 1 &&
          strstr(errs.items[0].message, "over the limit of 50000"));
    pk_schema_errors_free(&errs);
    json_object_set_new(json_object_get(in, "tetfill"), "max_tets", json_integer(100000));
    errs = (pk_schema_errors){0};
    CHECK(pk_process_validate_inputs(p, in, &service, &errs) == 0);
    pk_schema_errors_free(&errs);
    json_decref(in);
    alarm(0);
}

/* Confine {"file": name}; returns the error count, *out the rewritten path. */
static size_t confine(const char *input_dir, const char *name, char *rule, char *out)
{
    json_t *in = tetfill(name);
    pk_schema_errors errs = {0};
    size_t n = pk_input_files_confine(in, input_dir, 1000, &errs);
    if (rule)
        snprintf(rule, 32, "%s", n ? errs.items[0].rule : "");
    if (n)
        CHECK(!strcmp(errs.items[0].pointer, "/domain/mesh/file"));
    if (out)
        snprintf(out, PATH_MAX, "%s",
                 json_string_value(json_object_get(
                     json_object_get(json_object_get(in, "domain"), "mesh"), "file")));
    pk_schema_errors_free(&errs);
    json_decref(in);
    return n;
}

static void test_confine(void)
{
    char in[128], rule[32], out[PATH_MAX], real[PATH_MAX], want[PATH_MAX + 16];
    snprintf(in, sizeof in, "%s/in", dir);
    CHECK(realpath(in, real) != NULL);
    CHECK(confine(NULL, at("small.txt"), rule, NULL) == 1 && !strcmp(rule, "serverPath"));
    CHECK(confine("", "m.msh", rule, NULL) == 1 && !strcmp(rule, "serverPath"));
    /* accepted: relative, absolute inside, through the configured name, a TetGen base */
    CHECK(confine(in, "m.msh", NULL, out) == 0);
    snprintf(want, sizeof want, "%s/./m.msh", real); /* opened beneath in/ (input_open.h) */
    CHECK_MSG(!strcmp(out, want), "%s", out);
    /* at run time: a symlink inside is followed, one out (out.msh) is not,
     * nor ".." — whatever the path was when it was checked */
    char err[512], p[PATH_MAX + 32];
    snprintf(p, sizeof p, "%s/./link_in.msh", real);
    int fd = pk_input_open(p, 0, err, sizeof err);
    CHECK_MSG(fd >= 0, "%s", err);
    if (fd >= 0)
        close(fd);
    snprintf(p, sizeof p, "%s/./out.msh", real);
    CHECK_MSG(pk_input_open(p, 0, err, sizeof err) < 0 && strstr(err, "leads outside"), "%s", err);
    snprintf(p, sizeof p, "%s/./../small.txt", real);
    CHECK_MSG(pk_input_open(p, 0, err, sizeof err) < 0 && strstr(err, "leads outside"), "%s", err);
    CHECK(confine(in, at("in/m.msh"), NULL, NULL) == 0);
    CHECK(confine(in, "sub/../m.msh", rule, NULL) == 1 && !strcmp(rule, "inputDir"));
    CHECK(confine(in, "base", NULL, out) == 0);
    CHECK(confine(in, "base.node", NULL, NULL) == 0);
    CHECK(confine(in, "link_in.msh", NULL, NULL) == 0);
    /* refused */
    const char *bad[] = {"../small.txt", at("small.txt"), "/etc/passwd", "out.msh",
                         "zero.msh",     "fifo.msh",      "big.msh",     "nope.msh",
                         "sub",          "bad",           "..",          "dirlink/x.msh"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        CHECK_MSG(confine(in, bad[i], rule, NULL) == 1 && !strcmp(rule, "inputDir"), "%s", bad[i]);
}

int main(void)
{
    signal(SIGALRM, on_alarm);
    snprintf(dir, sizeof dir, "/tmp/test_input_files.XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    put("small.txt", "hello\n");
    mkfifo(at("fifo"), 0600);
    symlink("/dev/zero", at("zero.msh"));
    symlink(at("fifo"), at("fifo.msh"));
    put("pair.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
    mkfifo(at("pair.ele"), 0600);
    /* the input directory */
    mkdir(at("in"), 0700);
    mkdir(at("in/sub"), 0700);
    put("in/m.msh", "$MeshFormat\n");
    put("in/base.node", "4 3 0 0\n");
    put("in/base.ele", "1 4 0\n");
    put("in/bad.node", "4 3 0 0\n");
    symlink(at("small.txt"), at("in/bad.ele")); /* the pair's second file leads out */
    symlink(at("small.txt"), at("in/out.msh"));
    symlink("/dev/zero", at("in/zero.msh"));
    mkfifo(at("in/fifo.msh"), 0600);
    symlink("m.msh", at("in/link_in.msh"));
    symlink(dir, at("in/dirlink"));
    {
        char big[2000];
        memset(big, 'x', sizeof big - 1);
        big[sizeof big - 1] = 0;
        put("in/big.msh", big);
    }
    RUN(test_open_refuses_special_files);
    RUN(test_readers_refuse_special_files);
    RUN(test_service_checks_open_nothing);
    RUN(test_confine);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    (void)!system(cmd);
    return check_summary();
}
