/* input_links.c — the walker over file inputs given by link ({"href": ...}).
 * Contract: api/inputs/input_links.h. */
#include "input_links.h"

#include <stdio.h>
#include <string.h>

typedef struct {
    void (*fn)(json_t *, const char *, const char *, void *);
    void *ctx;
    const char *key; /* the string member looked for */
    int alone;       /* 1: only objects with no other member */
    size_t count;
    char ptr[256];
} walker;

static void walk(walker *w, json_t *v)
{
    size_t len = strlen(w->ptr);
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
            size_t o = len; /* RFC 6901 escaping of the key */
            w->ptr[o++] = '/';
            for (const char *c = key; *c && o + 3 < sizeof w->ptr; c++) {
                if (*c == '~' || *c == '/') {
                    w->ptr[o++] = '~';
                    w->ptr[o++] = *c == '~' ? '0' : '1';
                } else {
                    w->ptr[o++] = *c;
                }
            }
            w->ptr[o] = 0;
            walk(w, child);
            w->ptr[len] = 0;
        }
    } else if (json_is_array(v)) {
        size_t i;
        json_t *child;
        json_array_foreach (v, i, child) {
            if (!json_is_object(child) && !json_is_array(child))
                continue;
            snprintf(w->ptr + len, sizeof w->ptr - len, "/%zu", i);
            walk(w, child);
            w->ptr[len] = 0;
        }
    }
}

size_t pk_input_links_each(json_t *inputs,
                           void (*fn)(json_t *link, const char *href, const char *pointer,
                                      void *ctx),
                           void *ctx)
{
    walker w = {.fn = fn, .ctx = ctx, .key = "href", .alone = 1};
    walk(&w, inputs);
    return w.count;
}

size_t pk_input_files_each(json_t *inputs,
                           void (*fn)(json_t *obj, const char *file, const char *pointer,
                                      void *ctx),
                           void *ctx)
{
    walker w = {.fn = fn, .ctx = ctx, .key = "file", .alone = 0};
    walk(&w, inputs);
    return w.count;
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
