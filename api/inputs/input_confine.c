/* input_confine.c — server paths a request may name ({"file": ...}) kept
 * inside the input directory.  Contract: api/inputs/input_confine.h. */
#include "input_confine.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "input_links.h"
#include "input_open.h"

typedef struct {
    const char *dir;     /* as configured */
    char root[PATH_MAX]; /* resolved; "" when unusable */
    long long max_bytes;
    pk_schema_errors *errs;
} confine_ctx;

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

static int inside(const char *root, const char *path)
{
    size_t n = strlen(root);
    return strncmp(path, root, n) == 0 && (path[n] == '/' || (n == 1 && root[0] == '/'));
}

static int has_dotdot(const char *p)
{
    for (const char *s = p; (s = strstr(s, "..")) != NULL; s += 2)
        if ((s == p || s[-1] == '/') && (s[2] == 0 || s[2] == '/'))
            return 1;
    return 0;
}

/* One file the reader would open: 1 accepted, 0 absent, -1 refused (why). */
static int check_file(const confine_ctx *c, const char *path, const char **why)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return errno == ENOENT || errno == ENOTDIR ? 0 : (*why = "cannot be looked up", -1);
    char real[PATH_MAX];
    if (!realpath(path, real) || !inside(c->root, real)) {
        *why = "leads outside the input directory";
        return -1;
    }
    if (stat(real, &st) != 0 || !S_ISREG(st.st_mode)) {
        *why = "is not a regular file";
        return -1;
    }
    if ((long long)st.st_size > c->max_bytes) {
        *why = "is over input_max_bytes";
        return -1;
    }
    return 1;
}

/* 0 with the rewritten path in out, or -1 with why. */
static int confine(const confine_ctx *c, const char *file, char out[PATH_MAX + 8], size_t n,
                   const char **why)
{
    if (!c->root[0]) {
        *why = "the input directory is not available";
        return -1;
    }
    if (has_dotdot(file)) {
        *why = "\"..\" leaves the input directory";
        return -1;
    }
    char cand[PATH_MAX];
    if (file[0] == '/') {
        /* only under the directory as configured or as resolved: no other
         * absolute path is looked up, so nothing tells whether it exists */
        if (!inside(c->root, file) && !inside(c->dir, file)) {
            *why = "is outside the input directory";
            return -1;
        }
        if (snprintf(cand, sizeof cand, "%s", file) >= (int)sizeof cand)
            return *why = "is too long", -1;
    } else if (snprintf(cand, sizeof cand, "%s/%s", c->root, file) >= (int)sizeof cand) {
        *why = "is too long";
        return -1;
    }
    /* the directory resolved, the last name kept: what the worker opens */
    char *slash = strrchr(cand, '/'), dir[PATH_MAX];
    *slash = 0;
    const char *name = slash + 1;
    if (!*name || !strcmp(name, ".")) {
        *why = "is not a regular file";
        return -1;
    }
    if (!realpath(*cand ? cand : "/", dir) || !(inside(c->root, dir) || !strcmp(c->root, dir))) {
        *why = "is not a file in the input directory";
        return -1;
    }
    /* what the worker opens beneath the input directory (input_open.h) */
    const char *rel = dir + strlen(c->root);
    rel += *rel == '/';
    if (snprintf(out, n, "%s" PK_INPUT_BENEATH "%s%s%s", strcmp(c->root, "/") ? c->root : "", rel,
                 *rel ? "/" : "", name) >= (int)n) {
        *why = "is too long";
        return -1;
    }
    /* the files the readers open: the name itself, and for TetGen the
     * <base>.node / <base>.ele pair (mesh_io.h) */
    char base[PATH_MAX + 8], node[PATH_MAX + 16], ele[PATH_MAX + 16];
    snprintf(base, sizeof base, "%s", out);
    char *dot = strrchr(base, '.');
    if (dot && dot > strrchr(base, '/') && (!strcmp(dot, ".node") || !strcmp(dot, ".ele")))
        *dot = 0;
    snprintf(node, sizeof node, "%s.node", base);
    snprintf(ele, sizeof ele, "%s.ele", base);
    const char *files[3] = {out, ends_with(out, ".msh") ? NULL : node,
                            ends_with(out, ".msh") ? NULL : ele};
    int found = 0;
    for (int i = 0; i < 3; i++) {
        if (!files[i])
            continue;
        int rc = check_file(c, files[i], why);
        if (rc < 0)
            return -1;
        found += rc;
    }
    if (!found) {
        *why = "is not a file in the input directory";
        return -1;
    }
    return 0;
}

static void confine_one(json_t *obj, const char *file, const char *pointer, void *vctx)
{
    confine_ctx *c = vctx;
    char ptr[300], out[PATH_MAX + 8];
    const char *why = NULL;
    snprintf(ptr, sizeof ptr, "%s/file", pointer);
    if (!c->dir || !c->dir[0]) {
        pk_schema_errors_add(c->errs, ptr, "serverPath",
                             "the service takes no server path: upload the file (POST /files) "
                             "and give {\"href\": \"/files/<sha256>\"}%s",
                             strstr(pointer, "rve")
                                 ? ", or {\"href\": "
                                   "\"/jobs/<id>/results/result\"} for a finished job's result"
                                 : "");
        return;
    }
    if (confine(c, file, out, sizeof out, &why) != 0) {
        pk_schema_errors_add(c->errs, ptr, "inputDir",
                             "\"%.200s\" %s (only regular files inside "
                             "the service's input directory, up to %lld bytes)",
                             file, why, c->max_bytes);
        return;
    }
    json_object_set_new(obj, "file", json_string(out));
}

size_t pk_input_files_confine(json_t *inputs, const char *input_dir, long long max_bytes,
                              pk_schema_errors *errs)
{
    size_t before = errs->n;
    confine_ctx c = {.dir = input_dir, .max_bytes = max_bytes, .errs = errs};
    if (input_dir && input_dir[0] && !realpath(input_dir, c.root))
        c.root[0] = 0;
    pk_input_files_each(inputs, confine_one, &c);
    return errs->n - before;
}
