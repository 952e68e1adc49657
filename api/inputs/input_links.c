/* input_links.c — the walker over file inputs given by link ({"href": ...}).
 * Contract: api/inputs/input_links.h. */
#include "input_links.h"

#include "json_depth.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    void (*fn)(json_t *, const char *, const char *, void *);
    void *ctx;
    const char *key; /* the string member looked for */
    int alone;       /* 1: only objects with no other member */
    size_t count;
    char *ptr; /* the JSON pointer of the current value, grown with the walk */
    size_t cap;
    int oom;
} walker;

/* Room for need more bytes after len (and the terminator). */
static int reserve(walker *w, size_t len, size_t need)
{
    if (len + need + 1 <= w->cap)
        return 0;
    size_t cap = w->cap ? w->cap : 64;
    while (cap < len + need + 1)
        cap *= 2;
    char *p = realloc(w->ptr, cap);
    if (!p) {
        w->oom = 1;
        return -1;
    }
    w->ptr = p;
    w->cap = cap;
    return 0;
}

static void walk(walker *w, json_t *v, size_t len, int depth)
{
    /* Bodies are depth-checked before they reach here (PK_JSON_MAX_DEPTH);
     * job files from disk are not, so the walk stops there too. */
    if (w->oom || depth > PK_JSON_MAX_DEPTH)
        return;
    if (json_is_object(v)) {
        json_t *s = json_object_get(v, w->key);
        if (json_is_string(s) && (!w->alone || json_object_size(v) == 1)) {
            w->count++;
            w->fn(v, json_string_value(s), w->ptr, w->ctx);
            return;
        }
        const char *key;
        json_t *child;
        json_object_foreach (v, key, child) {
            if (!json_is_object(child) && !json_is_array(child))
                continue;
            if (reserve(w, len, 1 + 2 * strlen(key)) != 0)
                return;
            size_t o = len; /* RFC 6901 escaping of the key */
            w->ptr[o++] = '/';
            for (const char *c = key; *c; c++) {
                if (*c == '~' || *c == '/') {
                    w->ptr[o++] = '~';
                    w->ptr[o++] = *c == '~' ? '0' : '1';
                } else {
                    w->ptr[o++] = *c;
                }
            }
            w->ptr[o] = 0;
            walk(w, child, o, depth + 1);
            w->ptr[len] = 0;
        }
    } else if (json_is_array(v)) {
        size_t i;
        json_t *child;
        json_array_foreach (v, i, child) {
            if (!json_is_object(child) && !json_is_array(child))
                continue;
            if (reserve(w, len, 24) != 0)
                return;
            int n = snprintf(w->ptr + len, w->cap - len, "/%zu", i);
            walk(w, child, len + (size_t)n, depth + 1);
            w->ptr[len] = 0;
        }
    }
}

static size_t walk_all(walker *w, json_t *inputs)
{
    if (reserve(w, 0, 0) == 0) {
        w->ptr[0] = 0;
        walk(w, inputs, 0, 0);
    }
    free(w->ptr);
    return w->count;
}

size_t pk_input_links_each(json_t *inputs,
                           void (*fn)(json_t *link, const char *href, const char *pointer,
                                      void *ctx),
                           void *ctx)
{
    walker w = {.fn = fn, .ctx = ctx, .key = "href", .alone = 1};
    return walk_all(&w, inputs);
}

size_t pk_input_files_each(json_t *inputs,
                           void (*fn)(json_t *obj, const char *file, const char *pointer,
                                      void *ctx),
                           void *ctx)
{
    walker w = {.fn = fn, .ctx = ctx, .key = "file", .alone = 0};
    return walk_all(&w, inputs);
}

static void refuse(json_t *link, const char *href, const char *pointer, void *ctx)
{
    (void)link;
    char p[300];
    snprintf(p, sizeof p, "%s/href", pointer);
    pk_schema_errors_add(ctx, p, "href",
                         "links (%s) are resolved by packd serve; a job file names the file by "
                         "path: {\"file\": \"...\"}",
                         href);
}

size_t pk_input_links_refuse(json_t *inputs, pk_schema_errors *errs)
{
    size_t before = errs->n;
    pk_input_links_each(inputs, refuse, errs);
    return errs->n - before;
}
