/* targets.h — the fuzz targets: one function per untrusted input, fed raw
 * bytes.  The libFuzzer harnesses (tests/fuzz/fuzz_<name>.c, make fuzz) call
 * them, and so does tests/unit/test_fuzz_corpus.c, which replays the
 * committed corpus (tests/fuzz/corpus/<name>/, including every input that
 * once crashed or hung) in the ordinary and the sanitized build.
 *
 *   request  a POST /processes/{id}/execution body, as route_execute.c
 *            checks it: caps, server paths (refused, then confined to an
 *            input directory), the process checks in the service context
 *   gmsh     a Gmsh .msh file through pk_mesh_from_json (read + mesh check)
 *            and through the 2D reader of the fe2 macro mesh (pk_mesh2d_read_msh)
 *   tetgen   a TetGen pair: the bytes up to the first NUL are <base>.node,
 *            the rest <base>.ele
 *   h5_rve   an HDF5 file through the RVE reader pk_h5_read_particles; the
 *            reader must leave no HDF5 object open.  libhdf5 itself is not
 *            ours to fix: for forged sizes it asks for blocks of gigabytes
 *            (without ASan such a file fails in 0.3 s and 16 MB, under ASan
 *            filling the block timed out) and it leaks a few bytes on some
 *            error paths, so FUZZ_SANITIZER_OPTIONS makes allocations over
 *            512 MB fail and suppresses leaks inside libhdf5 only.  Files on
 *            which libhdf5 itself faults are in tests/fuzz/hdf5-known/. */
#ifndef PK_FUZZ_TARGETS_H
#define PK_FUZZ_TARGETS_H

#include <hdf5.h>
#include <jansson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api/results/h5_result.h"
#include "api/http/http_process_doc.h"
#include "api/inputs/input_confine.h"
#include "api/mesh/mesh_io.h"
#include "api/process.h"

static char fuzz_scratch[64];

static inline void fuzz_cleanup(void)
{
    static const char *const names[] = {"in/m.msh", "in", "f.msh", "t.node", "t.ele", "r.h5"};
    char p[128];
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        snprintf(p, sizeof p, "%s/%s", fuzz_scratch, names[i]);
        remove(p);
    }
    rmdir(fuzz_scratch);
}

/* A scratch directory for this process (files are rewritten per input). */
static inline const char *fuzz_dir(void)
{
    char *dir = fuzz_scratch;
    if (!dir[0]) {
        snprintf(dir, sizeof fuzz_scratch, "/tmp/packd-fuzz.XXXXXX");
        if (!mkdtemp(dir)) {
            perror("mkdtemp");
            abort();
        }
        atexit(fuzz_cleanup);
        char p[128];
        snprintf(p, sizeof p, "%s/in", dir); /* an input directory with one mesh */
        mkdir(p, 0700);
        snprintf(p, sizeof p, "%s/in/m.msh", dir);
        FILE *f = fopen(p, "w");
        if (f)
            fclose(f);
    }
    return dir;
}

static inline int fuzz_write(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    size_t w = size ? fwrite(data, 1, size, f) : 0;
    return fclose(f) == 0 && w == size ? 0 : -1;
}

static inline void fuzz_request(const uint8_t *data, size_t size)
{
    json_t *body = json_loadb((const char *)data, size, 0, NULL);
    json_t *inputs = json_object_get(body, "inputs");
    if (json_is_object(inputs)) {
        char in[128];
        snprintf(in, sizeof in, "%s/in", fuzz_dir());
        const pk_check_ctx request = {.service = 1};
        for (size_t k = 0; pk_processes[k]; k++) {
            const pk_process *p = pk_processes[k];
            for (int dir = 0; dir < 2; dir++) {
                json_t *copy = json_deep_copy(inputs);
                pk_schema_errors errs = {0};
                pk_process_apply_caps(p, copy, 100000, 600);
                if (pk_input_files_confine(copy, dir ? in : NULL, 1 << 20, &errs) == 0)
                    pk_process_validate_inputs(p, copy, &request, &errs);
                pk_schema_errors_free(&errs);
                json_decref(copy);
            }
        }
        /* the same object as a job file (pk_job_parse, not kept), still unread */
        const pk_process *proc;
        pk_schema_errors errs = {0};
        pk_job_parse(body, &request, &proc, NULL, &errs);
        pk_schema_errors_free(&errs);
    }
    json_decref(body);
}

static inline void fuzz_mesh_file(const char *file)
{
    json_t *j = json_pack("{s:s}", "file", file);
    pk_mesh m;
    pk_mesh_report rep;
    char err[512];
    if (pk_mesh_from_json(j, 20000, &m, &rep, err, sizeof err) == 0)
        pk_mesh_free(&m);
    json_decref(j);
}

static inline void fuzz_gmsh(const uint8_t *data, size_t size)
{
    char p[128];
    snprintf(p, sizeof p, "%s/f.msh", fuzz_dir());
    if (fuzz_write(p, data, size) == 0) {
        fuzz_mesh_file(p);
        pk_mesh2d m2;
        char err[512];
        if (pk_mesh2d_read_msh(p, 100000, &m2, err, sizeof err) == 0)
            pk_mesh2d_free(&m2);
    }
}

static inline void fuzz_tetgen(const uint8_t *data, size_t size)
{
    const uint8_t *nul = memchr(data, 0, size);
    size_t n_node = nul ? (size_t)(nul - data) : size;
    char base[128], p[160];
    snprintf(base, sizeof base, "%s/t", fuzz_dir());
    snprintf(p, sizeof p, "%s.node", base);
    if (fuzz_write(p, data, n_node) != 0)
        return;
    snprintf(p, sizeof p, "%s.ele", base);
    if (fuzz_write(p, nul ? nul + 1 : data, nul ? size - n_node - 1 : 0) != 0)
        return;
    fuzz_mesh_file(base);
}

static inline void fuzz_h5_rve(const uint8_t *data, size_t size)
{
    char p[128], err[512];
    snprintf(p, sizeof p, "%s/r.h5", fuzz_dir());
    if (fuzz_write(p, data, size) != 0)
        return;
    pk_box b;
    pk_particles q;
    if (pk_h5_read_particles(p, &b, &q, err, sizeof err) == 0)
        pk_particles_free(&q);
    if (H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL) != 0) {
        fprintf(stderr, "pk_h5_read_particles left %zd HDF5 objects open\n",
                (ssize_t)H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL));
        abort();
    }
}

/* Sanitizer settings for binaries that run the targets (see h5_rve above);
 * without a sanitizer these hooks are never called. */
#define FUZZ_SANITIZER_OPTIONS                                                                     \
    const char *__asan_default_options(void);                                                      \
    const char *__asan_default_options(void)                                                       \
    {                                                                                              \
        return "allocator_may_return_null=1:max_allocation_size_mb=512";                           \
    }                                                                                              \
    const char *__lsan_default_suppressions(void);                                                 \
    const char *__lsan_default_suppressions(void) { return "leak:libhdf5\n"; }

#endif
