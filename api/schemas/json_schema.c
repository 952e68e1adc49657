/* json_schema.c — the JSON Schema (2020-12) subset described in json_schema.h.
 *
 * One recursive walk over (schema, instance).  The instance location is kept
 * as a JSON pointer in a buffer that grows and shrinks with the walk; every
 * error copies it.  Applicators that only need a yes/no answer (anyOf, oneOf,
 * not, if) evaluate their branches as a "trial": the same walk into a scratch
 * error list capped at one error.  Schema bugs found during a trial (rule
 * "schema") are copied to the real list, so a broken branch never silently
 * turns into a pass or a fail. */
#include "json_schema.h"
#include "schemas_embedded.h"

#include <math.h>
#include <pthread.h>
#include <regex.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- errors */

void pk_schema_errors_free(pk_schema_errors *e)
{
    if (!e)
        return;
    free(e->items);
    e->items = NULL;
    e->n = e->cap = 0;
}

/* Copy src into dst[cap] (cap > 0), truncating without splitting a UTF-8
 * sequence. */
static void copy_trunc(char *dst, size_t cap, const char *src)
{
    size_t n = strlen(src);
    if (n >= cap) {
        n = cap - 1;
        while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80)
            n--;
    }
    memcpy(dst, src, n);
    dst[n] = '\0';
}

static int errors_addv(pk_schema_errors *e, const char *pointer, const char *rule, const char *fmt,
                       va_list ap)
{
    if (!e)
        return 0;
    if (e->n == e->cap) {
        size_t cap = e->cap ? 2 * e->cap : 8;
        pk_schema_error *it = realloc(e->items, cap * sizeof *it);
        if (!it)
            return 0;
        e->items = it;
        e->cap = cap;
    }
    pk_schema_error *x = &e->items[e->n];
    copy_trunc(x->pointer, sizeof x->pointer, pointer ? pointer : "");
    copy_trunc(x->rule, sizeof x->rule, rule ? rule : "");
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    copy_trunc(x->message, sizeof x->message, msg);
    e->n++;
    return 1;
}

void pk_schema_errors_add(pk_schema_errors *e, const char *pointer, const char *rule,
                          const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    errors_addv(e, pointer, rule, fmt, ap);
    va_end(ap);
}

json_t *pk_schema_errors_json(const pk_schema_errors *e)
{
    json_t *arr = json_array();
    if (!arr || !e)
        return arr;
    for (size_t i = 0; i < e->n; i++) {
        const pk_schema_error *x = &e->items[i];
        json_array_append_new(arr,
                              json_pack("{s:s, s:s, s:s}", "pointer", x->pointer, "rule", x->rule,
                                        "message", x->message));
    }
    return arr;
}

/* ------------------------------------------------------- value rendering */

/* Shortest "%g" form that reads back as the same double. */
static void fmt_double(double d, char *buf, size_t n)
{
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, n, "%.*g", prec, d);
        if (strtod(buf, NULL) == d)
            return;
    }
}

/* Compact JSON of v, truncated to about `max` bytes with "...". */
static void render(const json_t *v, char *buf, size_t n)
{
    if (n == 0)
        return;
    if (json_is_integer(v)) {
        snprintf(buf, n, "%lld", (long long)json_integer_value(v));
        return;
    }
    if (json_is_real(v)) {
        fmt_double(json_real_value(v), buf, n);
        return;
    }
    char *s = v ? json_dumps(v, JSON_ENCODE_ANY | JSON_COMPACT) : NULL;
    if (!s) {
        snprintf(buf, n, "?");
        return;
    }
    size_t max = n < 72 ? n : 72;
    if (strlen(s) >= max && max > 4) {
        size_t cut = max - 4;
        while (cut > 0 && ((unsigned char)s[cut] & 0xC0) == 0x80)
            cut--;
        memcpy(buf, s, cut);
        memcpy(buf + cut, "...", 4);
    } else {
        copy_trunc(buf, n, s);
    }
    free(s);
}

static const char *type_name(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT: return "object";
    case JSON_ARRAY: return "array";
    case JSON_STRING: return "string";
    case JSON_INTEGER: return "integer";
    case JSON_REAL: return "number";
    case JSON_TRUE:
    case JSON_FALSE: return "boolean";
    case JSON_NULL: return "null";
    }
    return "?";
}

/* "string \"abc\"", "integer 3", "object", "null", ... */
static void describe(const json_t *v, char *buf, size_t n)
{
    if (json_is_object(v) || json_is_array(v) || json_is_null(v)) {
        snprintf(buf, n, "%s", type_name(v));
        return;
    }
    char r[96];
    render(v, r, sizeof r);
    snprintf(buf, n, "%s %s", type_name(v), r);
}

/* JSON Schema equality: like json_equal, except that numbers compare by
 * value (1 == 1.0), also inside arrays and objects. */
static int values_equal(json_t *a, json_t *b)
{
    if (json_is_number(a) && json_is_number(b)) {
        if (json_is_integer(a) && json_is_integer(b))
            return json_integer_value(a) == json_integer_value(b);
        return json_number_value(a) == json_number_value(b);
    }
    if (json_is_array(a) && json_is_array(b)) {
        size_t n = json_array_size(a);
        if (n != json_array_size(b))
            return 0;
        for (size_t i = 0; i < n; i++)
            if (!values_equal(json_array_get(a, i), json_array_get(b, i)))
                return 0;
        return 1;
    }
    if (json_is_object(a) && json_is_object(b)) {
        if (json_object_size(a) != json_object_size(b))
            return 0;
        const char *k;
        json_t *va;
        json_object_foreach (a, k, va) {
            json_t *vb = json_object_get(b, k);
            if (!vb || !values_equal(va, vb))
                return 0;
        }
        return 1;
    }
    return json_equal(a, b);
}

/* -1, 0, 1; ints as long long when both are ints, otherwise doubles. */
static int num_cmp(const json_t *a, const json_t *b)
{
    if (json_is_integer(a) && json_is_integer(b)) {
        long long x = json_integer_value(a), y = json_integer_value(b);
        return (x > y) - (x < y);
    }
    double x = json_number_value(a), y = json_number_value(b);
    return (x > y) - (x < y);
}

static int is_integral(const json_t *v)
{
    if (json_is_integer(v))
        return 1;
    if (!json_is_real(v))
        return 0;
    double d = json_real_value(v);
    return isfinite(d) && floor(d) == d;
}

int pk_json_int(const json_t *v, long long *out)
{
    if (json_is_integer(v)) {
        *out = (long long)json_integer_value(v);
        return 0;
    }
    if (!is_integral(v))
        return -1;
    double d = json_real_value(v);
    if (fabs(d) > 9007199254740992.0) /* 2^53: beyond it not every integer is exact */
        return -1;
    *out = (long long)d;
    return 0;
}

/* A non-negative integer keyword value (3 or 3.0). */
static int get_count(const json_t *v, size_t *out)
{
    if (!is_integral(v))
        return 0;
    double d = json_number_value(v);
    if (d < 0 || d > 1e15)
        return 0;
    *out = (size_t)d;
    return 1;
}

static size_t utf8_len(const char *s, size_t bytes)
{
    size_t n = 0;
    for (size_t i = 0; i < bytes; i++)
        if (((unsigned char)s[i] & 0xC0) != 0x80)
            n++;
    return n;
}

/* ------------------------------------------------------------ validation */

#define PTR_CAP 1024

typedef struct re_cache {
    struct re_cache *next;
    char *pattern;
    int ok;
    char why[128];
    regex_t re;
} re_cache;

typedef struct ref_frame {
    const json_t *schema, *instance;
} ref_frame;

typedef struct vctx {
    json_t *root; /* document that local "#/..." refs resolve in */
    pk_schema_loader loader;
    void *loader_ctx;
    pk_schema_errors *errs;
    size_t added, limit;
    int depth;
    ref_frame refs[PK_SCHEMA_MAX_DEPTH + 1];
    int nrefs;
    char ptr[PTR_CAP];
    size_t plen;
    re_cache *res;
} vctx;

static int full(const vctx *c) { return c->added >= c->limit; }

static void err(vctx *c, const char *rule, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void err(vctx *c, const char *rule, const char *fmt, ...)
{
    if (full(c))
        return;
    va_list ap;
    va_start(ap, fmt);
    errors_addv(c->errs, c->ptr, rule, fmt, ap);
    va_end(ap);
    c->added++;
}

/* Append one escaped reference token; returns the length to restore. */
static size_t push_key(vctx *c, const char *key)
{
    size_t saved = c->plen;
    char tmp[PTR_CAP];
    size_t n = 0;
    tmp[n++] = '/';
    for (const char *p = key; *p && n + 2 < sizeof tmp; p++) {
        if (*p == '~') {
            tmp[n++] = '~';
            tmp[n++] = '0';
        } else if (*p == '/') {
            tmp[n++] = '~';
            tmp[n++] = '1';
        } else {
            tmp[n++] = *p;
        }
    }
    if (c->plen + n < PTR_CAP) {
        memcpy(c->ptr + c->plen, tmp, n);
        c->plen += n;
        c->ptr[c->plen] = '\0';
    }
    return saved;
}

static size_t push_index(vctx *c, size_t i)
{
    char k[32];
    snprintf(k, sizeof k, "%zu", i);
    return push_key(c, k);
}

static void pop(vctx *c, size_t saved)
{
    c->plen = saved;
    c->ptr[saved] = '\0';
}

static void validate(vctx *c, json_t *schema, json_t *inst);

/* A keyword handler: the schema object s holding the keyword, its value v,
 * the instance.  Not every handler needs every argument. */
#define UNUSED __attribute__((unused))
#define KW(name)                                                                                   \
    static void name(UNUSED vctx *c, UNUSED json_t *s, UNUSED json_t *v, UNUSED json_t *inst)

/* Evaluate `schema` without reporting: returns 1 if the instance fails.
 * Schema bugs met on the way are still reported. */
static int trial(vctx *c, json_t *schema, json_t *inst)
{
    pk_schema_errors tmp = {0};
    pk_schema_errors *saved_errs = c->errs;
    size_t saved_added = c->added, saved_limit = c->limit;
    c->errs = &tmp;
    c->added = 0;
    c->limit = 1;
    validate(c, schema, inst);
    int failed = c->added > 0;
    c->errs = saved_errs;
    c->added = saved_added;
    c->limit = saved_limit;
    for (size_t i = 0; i < tmp.n && !full(c); i++) {
        if (strcmp(tmp.items[i].rule, "schema") == 0) {
            pk_schema_errors_add(c->errs, tmp.items[i].pointer, "schema", "%s",
                                 tmp.items[i].message);
            c->added++;
        }
    }
    pk_schema_errors_free(&tmp);
    return failed;
}

static int is_schema(const json_t *s) { return json_is_object(s) || json_is_boolean(s); }

/* ---- $ref */

/* Decode one reference token of a URI-fragment JSON pointer in place:
 * percent-decoding, then ~1 -> '/', ~0 -> '~'.  0 on a malformed token. */
static int decode_token(char *t)
{
    char *w = t;
    for (char *r = t; *r; r++) {
        if (*r == '%' && r[1] && r[2]) {
            char hex[3] = {r[1], r[2], 0};
            char *end;
            long v = strtol(hex, &end, 16);
            if (*end || v <= 0)
                return 0;
            *w++ = (char)v;
            r += 2;
        } else {
            *w++ = *r;
        }
    }
    *w = '\0';
    w = t;
    for (char *r = t; *r; r++) {
        if (*r == '~') {
            if (r[1] == '0')
                *w++ = '~';
            else if (r[1] == '1')
                *w++ = '/';
            else
                return 0;
            r++;
        } else {
            *w++ = *r;
        }
    }
    *w = '\0';
    return 1;
}

/* Resolve `ref` from document `root`: returns the target and sets *root_out to
 * the document it lives in, or NULL with a reason in why[]. */
static json_t *resolve_ref(vctx *c, const char *ref, json_t *root, json_t **root_out, char *why,
                           size_t whylen)
{
    char dummy[8] = "";
    if (!why) {
        why = dummy;
        whylen = sizeof dummy;
    }
    const char *hash = strchr(ref, '#');
    size_t flen = hash ? (size_t)(hash - ref) : strlen(ref);
    json_t *doc = root;
    if (flen > 0) {
        char file[256];
        if (flen >= sizeof file) {
            snprintf(why, whylen, "file name too long");
            return NULL;
        }
        memcpy(file, ref, flen);
        file[flen] = '\0';
        const char *base = strrchr(file, '/');
        base = base ? base + 1 : file;
        if (!c->loader) {
            snprintf(why, whylen, "no loader for cross-file references");
            return NULL;
        }
        doc = c->loader(base, c->loader_ctx);
        if (!doc) {
            snprintf(why, whylen, "unknown schema file \"%.120s\"", base);
            return NULL;
        }
    }
    if (!doc) {
        snprintf(why, whylen, "no root document");
        return NULL;
    }
    const char *frag = hash ? hash + 1 : "";
    if (*frag && *frag != '/') {
        snprintf(why, whylen, "anchors are not supported (use a JSON pointer \"#/...\")");
        return NULL;
    }
    char *buf = strdup(frag);
    if (!buf) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    json_t *cur = doc;
    char *p = *buf ? buf + 1 : NULL; /* skip the leading '/' */
    while (p && cur) {
        char *slash = strchr(p, '/');
        if (slash)
            *slash = '\0';
        if (!decode_token(p)) {
            snprintf(why, whylen, "malformed JSON pointer");
            cur = NULL;
            break;
        }
        if (json_is_object(cur)) {
            cur = json_object_get(cur, p);
        } else if (json_is_array(cur)) {
            char *end;
            unsigned long long i = strtoull(p, &end, 10);
            if (!*p || *end || (p[0] == '0' && p[1]) || p[0] == '-' || p[0] == '+')
                cur = NULL;
            else
                cur = json_array_get(cur, (size_t)i);
        } else {
            cur = NULL;
        }
        p = slash ? slash + 1 : NULL;
    }
    free(buf);
    if (!cur) {
        if (!*why)
            snprintf(why, whylen, "no such location");
        return NULL;
    }
    *root_out = doc;
    return cur;
}

KW(kw_ref)
{
    if (!json_is_string(v)) {
        err(c, "schema", "invalid schema: \"$ref\" must be a string");
        return;
    }
    const char *ref = json_string_value(v);
    char why[160] = "";
    json_t *newroot = NULL;
    json_t *target = resolve_ref(c, ref, c->root, &newroot, why, sizeof why);
    if (!target) {
        err(c, "schema", "cannot resolve $ref \"%s\": %s", ref, why);
        return;
    }
    for (int i = 0; i < c->nrefs; i++) {
        if (c->refs[i].schema == target && c->refs[i].instance == inst) {
            err(c, "schema", "circular $ref \"%s\" (loops without consuming input)", ref);
            return;
        }
    }
    if (c->nrefs > PK_SCHEMA_MAX_DEPTH) {
        err(c, "schema", "$ref chain deeper than %d", PK_SCHEMA_MAX_DEPTH);
        return;
    }
    c->refs[c->nrefs].schema = target;
    c->refs[c->nrefs].instance = inst;
    c->nrefs++;
    json_t *oldroot = c->root;
    c->root = newroot;
    validate(c, target, inst);
    c->root = oldroot;
    c->nrefs--;
}

/* ---- generic */

/* 1 match, 0 no match, -1 unknown type name. */
static int type_matches(const char *t, const json_t *v)
{
    if (!strcmp(t, "object"))
        return json_is_object(v);
    if (!strcmp(t, "array"))
        return json_is_array(v);
    if (!strcmp(t, "string"))
        return json_is_string(v);
    if (!strcmp(t, "number"))
        return json_is_number(v);
    if (!strcmp(t, "integer"))
        return is_integral(v);
    if (!strcmp(t, "boolean"))
        return json_is_boolean(v);
    if (!strcmp(t, "null"))
        return json_is_null(v);
    return -1;
}

KW(kw_type)
{
    char got[128];
    if (json_is_string(v)) {
        int m = type_matches(json_string_value(v), inst);
        if (m < 0) {
            err(c, "schema", "invalid schema: unknown type \"%s\"", json_string_value(v));
        } else if (!m) {
            describe(inst, got, sizeof got);
            err(c, "type", "must be %s (got %s)", json_string_value(v), got);
        }
        return;
    }
    if (!json_is_array(v) || json_array_size(v) == 0) {
        err(c, "schema", "invalid schema: \"type\" must be a string or a non-empty array");
        return;
    }
    size_t i;
    json_t *t;
    int any = 0;
    char list[160] = "";
    json_array_foreach (v, i, t) {
        if (!json_is_string(t) || type_matches(json_string_value(t), inst) < 0) {
            err(c, "schema", "invalid schema: bad entry in \"type\"");
            return;
        }
        if (type_matches(json_string_value(t), inst))
            any = 1;
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", json_string_value(t));
    }
    if (!any) {
        describe(inst, got, sizeof got);
        err(c, "type", "must be one of %s (got %s)", list, got);
    }
}

KW(kw_enum)
{
    if (!json_is_array(v)) {
        err(c, "schema", "invalid schema: \"enum\" must be an array");
        return;
    }
    size_t i;
    json_t *e;
    json_array_foreach (v, i, e)
        if (values_equal(e, inst))
            return;
    char list[200] = "", r[96], got[96];
    json_array_foreach (v, i, e) {
        size_t l = strlen(list);
        render(e, r, sizeof r);
        if (l + strlen(r) + 8 >= sizeof list) {
            snprintf(list + l, sizeof list - l, ", ...");
            break;
        }
        snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", r);
    }
    render(inst, got, sizeof got);
    err(c, "enum", "must be one of %s (got %s)", list, got);
}

KW(kw_const)
{
    if (values_equal(v, inst))
        return;
    char want[96], got[96];
    render(v, want, sizeof want);
    render(inst, got, sizeof got);
    err(c, "const", "must be %s (got %s)", want, got);
}

/* ---- objects */

KW(kw_properties)
{
    if (!json_is_object(v)) {
        err(c, "schema", "invalid schema: \"properties\" must be an object");
        return;
    }
    if (!json_is_object(inst))
        return;
    const char *k;
    json_t *sub;
    json_object_foreach (v, k, sub) {
        if (full(c))
            return;
        json_t *iv = json_object_get(inst, k);
        if (!iv)
            continue;
        size_t saved = push_key(c, k);
        validate(c, sub, iv);
        pop(c, saved);
    }
}

static int string_array(const json_t *v)
{
    if (!json_is_array(v))
        return 0;
    size_t i;
    json_t *e;
    json_array_foreach (v, i, e)
        if (!json_is_string(e))
            return 0;
    return 1;
}

KW(kw_required)
{
    if (!string_array(v)) {
        err(c, "schema", "invalid schema: \"required\" must be an array of strings");
        return;
    }
    if (!json_is_object(inst))
        return;
    size_t i;
    json_t *e;
    json_array_foreach (v, i, e) {
        if (!json_object_get(inst, json_string_value(e)))
            err(c, "required", "missing required property \"%s\"", json_string_value(e));
    }
}

KW(kw_additional)
{
    if (!is_schema(v)) {
        err(c, "schema", "invalid schema: \"additionalProperties\" must be a schema");
        return;
    }
    if (!json_is_object(inst))
        return;
    json_t *props = json_object_get(s, "properties");
    if (!json_is_object(props))
        props = NULL;
    const char *k;
    json_t *iv;
    json_object_foreach (inst, k, iv) {
        if (full(c))
            return;
        if (props && json_object_get(props, k))
            continue;
        size_t saved = push_key(c, k);
        if (json_is_false(v)) {
            char allowed[200] = "";
            const char *pk;
            json_t *pv;
            if (props) {
                json_object_foreach (props, pk, pv) {
                    size_t l = strlen(allowed);
                    if (l + strlen(pk) + 8 >= sizeof allowed) {
                        snprintf(allowed + l, sizeof allowed - l, ", ...");
                        break;
                    }
                    snprintf(allowed + l, sizeof allowed - l, "%s%s", l ? ", " : "", pk);
                }
            }
            err(c, "additionalProperties", "unknown property \"%s\" (allowed: %s)", k,
                *allowed ? allowed : "none");
        } else {
            validate(c, v, iv);
        }
        pop(c, saved);
    }
}

static void count_kw(vctx *c, json_t *v, json_t *inst, const char *kw, int is_min, int want_array)
{
    size_t lim;
    if (!get_count(v, &lim)) {
        err(c, "schema", "invalid schema: \"%s\" must be a non-negative integer", kw);
        return;
    }
    if (want_array ? !json_is_array(inst) : !json_is_object(inst))
        return;
    size_t n = want_array ? json_array_size(inst) : json_object_size(inst);
    const char *what = want_array ? "items" : "properties";
    if (is_min && n < lim)
        err(c, kw, "must have at least %zu %s (got %zu)", lim, what, n);
    else if (!is_min && n > lim)
        err(c, kw, "must have at most %zu %s (got %zu)", lim, what, n);
}

KW(kw_minProperties) { count_kw(c, v, inst, "minProperties", 1, 0); }
KW(kw_maxProperties) { count_kw(c, v, inst, "maxProperties", 0, 0); }

KW(kw_dependentRequired)
{
    const char *k;
    json_t *deps;
    int ok = json_is_object(v);
    if (ok)
        json_object_foreach (v, k, deps)
            if (!string_array(deps))
                ok = 0;
    if (!ok) {
        err(c, "schema",
            "invalid schema: \"dependentRequired\" must map names to arrays of strings");
        return;
    }
    if (!json_is_object(inst))
        return;
    json_object_foreach (v, k, deps) {
        if (!json_object_get(inst, k))
            continue;
        size_t i;
        json_t *d;
        json_array_foreach (deps, i, d) {
            if (!json_object_get(inst, json_string_value(d)))
                err(c, "dependentRequired", "property \"%s\" requires property \"%s\"", k,
                    json_string_value(d));
        }
    }
}

/* ---- arrays */

KW(kw_items)
{
    if (!is_schema(v)) {
        err(c, "schema", "invalid schema: \"items\" must be a schema");
        return;
    }
    if (!json_is_array(inst))
        return;
    json_t *prefix = json_object_get(s, "prefixItems");
    size_t start = json_is_array(prefix) ? json_array_size(prefix) : 0;
    size_t n = json_array_size(inst);
    if (json_is_false(v)) {
        if (n > start) {
            size_t saved = push_index(c, start);
            err(c, "items", "unexpected item: at most %zu items allowed (got %zu)", start, n);
            pop(c, saved);
        }
        return;
    }
    for (size_t i = start; i < n && !full(c); i++) {
        size_t saved = push_index(c, i);
        validate(c, v, json_array_get(inst, i));
        pop(c, saved);
    }
}

KW(kw_prefixItems)
{
    if (!json_is_array(v)) {
        err(c, "schema", "invalid schema: \"prefixItems\" must be an array of schemas");
        return;
    }
    if (!json_is_array(inst))
        return;
    size_t n = json_array_size(inst);
    for (size_t i = 0; i < json_array_size(v) && i < n && !full(c); i++) {
        size_t saved = push_index(c, i);
        validate(c, json_array_get(v, i), json_array_get(inst, i));
        pop(c, saved);
    }
}

KW(kw_minItems) { count_kw(c, v, inst, "minItems", 1, 1); }
KW(kw_maxItems) { count_kw(c, v, inst, "maxItems", 0, 1); }

KW(kw_uniqueItems)
{
    if (!json_is_boolean(v)) {
        err(c, "schema", "invalid schema: \"uniqueItems\" must be a boolean");
        return;
    }
    if (json_is_false(v) || !json_is_array(inst))
        return;
    size_t n = json_array_size(inst);
    for (size_t j = 1; j < n && !full(c); j++) {
        for (size_t i = 0; i < j; i++) {
            if (values_equal(json_array_get(inst, i), json_array_get(inst, j))) {
                size_t saved = push_index(c, j);
                err(c, "uniqueItems", "must be unique: duplicate of item %zu", i);
                pop(c, saved);
                break;
            }
        }
    }
}

/* ---- numbers */

static void num_kw(vctx *c, json_t *v, json_t *inst, const char *kw, const char *op,
                   int fails_if_cmp_lt, int fails_if_eq, int fails_if_cmp_gt)
{
    if (!json_is_number(v)) {
        err(c, "schema", "invalid schema: \"%s\" must be a number", kw);
        return;
    }
    if (!json_is_number(inst))
        return;
    int cmp = num_cmp(inst, v);
    if ((cmp < 0 && fails_if_cmp_lt) || (cmp == 0 && fails_if_eq) || (cmp > 0 && fails_if_cmp_gt)) {
        char want[64], got[64];
        render(v, want, sizeof want);
        render(inst, got, sizeof got);
        err(c, kw, "must be %s %s (got %s)", op, want, got);
    }
}

KW(kw_minimum) { num_kw(c, v, inst, "minimum", ">=", 1, 0, 0); }
KW(kw_maximum) { num_kw(c, v, inst, "maximum", "<=", 0, 0, 1); }
KW(kw_exclusiveMinimum) { num_kw(c, v, inst, "exclusiveMinimum", ">", 1, 1, 0); }
KW(kw_exclusiveMaximum) { num_kw(c, v, inst, "exclusiveMaximum", "<", 0, 1, 1); }

KW(kw_multipleOf)
{
    if (!json_is_number(v) || json_number_value(v) <= 0) {
        err(c, "schema", "invalid schema: \"multipleOf\" must be a number > 0");
        return;
    }
    if (!json_is_number(inst))
        return;
    int ok;
    if (json_is_integer(v) && json_is_integer(inst)) {
        ok = json_integer_value(inst) % json_integer_value(v) == 0;
    } else {
        /* Relative tolerance, so that 0.3 is a multiple of 0.1. */
        double q = json_number_value(inst) / json_number_value(v);
        ok = isfinite(q) && fabs(q - nearbyint(q)) <= 1e-9 * fmax(1.0, fabs(q));
    }
    if (!ok) {
        char want[64], got[64];
        render(v, want, sizeof want);
        render(inst, got, sizeof got);
        err(c, "multipleOf", "must be a multiple of %s (got %s)", want, got);
    }
}

/* ---- strings */

KW(kw_minLength)
{
    size_t lim;
    if (!get_count(v, &lim)) {
        err(c, "schema", "invalid schema: \"minLength\" must be a non-negative integer");
        return;
    }
    if (!json_is_string(inst))
        return;
    size_t n = utf8_len(json_string_value(inst), json_string_length(inst));
    if (n < lim)
        err(c, "minLength", "must be at least %zu characters long (got %zu)", lim, n);
}

KW(kw_maxLength)
{
    size_t lim;
    if (!get_count(v, &lim)) {
        err(c, "schema", "invalid schema: \"maxLength\" must be a non-negative integer");
        return;
    }
    if (!json_is_string(inst))
        return;
    size_t n = utf8_len(json_string_value(inst), json_string_length(inst));
    if (n > lim)
        err(c, "maxLength", "must be at most %zu characters long (got %zu)", lim, n);
}

/* Rewrite the ECMA-262 shorthand classes \d \w \s (and \D \W \S outside
 * brackets) that schema authors habitually write into POSIX ERE; everything
 * else is passed through.  Caller frees. */
static char *ere_from_pattern(const char *in)
{
    size_t cap = strlen(in) * 16 + 1;
    char *out = malloc(cap);
    if (!out)
        return NULL;
    size_t n = 0;
    int in_bracket = 0;
#define EMIT(str) (memcpy(out + n, (str), strlen(str)), n += strlen(str))
    for (const char *p = in; *p; p++) {
        if (!in_bracket && *p == '[') {
            in_bracket = 1;
            out[n++] = *p;
            if (p[1] == '^')
                out[n++] = *++p;
            if (p[1] == ']')
                out[n++] = *++p;
            continue;
        }
        if (in_bracket && p[0] == '[' && (p[1] == ':' || p[1] == '.' || p[1] == '=')) {
            char close = p[1];
            const char *end = p + 2;
            while (*end && !(end[0] == close && end[1] == ']'))
                end++;
            if (*end) {
                memcpy(out + n, p, (size_t)(end + 2 - p));
                n += (size_t)(end + 2 - p);
                p = end + 1;
                continue;
            }
        }
        if (in_bracket && *p == ']') {
            in_bracket = 0;
            out[n++] = *p;
            continue;
        }
        if (*p == '\\' && p[1]) {
            const char *rep = NULL;
            switch (p[1]) {
            case 'd': rep = in_bracket ? "0-9" : "[0-9]"; break;
            case 'w': rep = in_bracket ? "A-Za-z0-9_" : "[A-Za-z0-9_]"; break;
            case 's': rep = in_bracket ? "[:space:]" : "[[:space:]]"; break;
            case 'D': rep = in_bracket ? NULL : "[^0-9]"; break;
            case 'W': rep = in_bracket ? NULL : "[^A-Za-z0-9_]"; break;
            case 'S': rep = in_bracket ? NULL : "[^[:space:]]"; break;
            default: break;
            }
            if (rep) {
                EMIT(rep);
                p++;
                continue;
            }
            out[n++] = *p++;
            out[n++] = *p;
            continue;
        }
        out[n++] = *p;
    }
#undef EMIT
    out[n] = '\0';
    return out;
}

static re_cache *get_regex(vctx *c, const char *pattern)
{
    for (re_cache *r = c->res; r; r = r->next)
        if (!strcmp(r->pattern, pattern))
            return r;
    re_cache *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->pattern = strdup(pattern);
    char *ere = ere_from_pattern(pattern);
    if (!r->pattern || !ere) {
        free(r->pattern);
        free(ere);
        free(r);
        return NULL;
    }
    int rc = regcomp(&r->re, ere, REG_EXTENDED | REG_NOSUB);
    free(ere);
    if (rc == 0) {
        r->ok = 1;
    } else {
        regerror(rc, &r->re, r->why, sizeof r->why);
        regfree(&r->re);
    }
    r->next = c->res;
    c->res = r;
    return r;
}

KW(kw_pattern)
{
    if (!json_is_string(v)) {
        err(c, "schema", "invalid schema: \"pattern\" must be a string");
        return;
    }
    re_cache *r = get_regex(c, json_string_value(v));
    if (!r) {
        err(c, "schema", "out of memory compiling pattern");
        return;
    }
    if (!r->ok) {
        err(c, "schema", "invalid schema: bad pattern \"%s\": %s", json_string_value(v), r->why);
        return;
    }
    if (!json_is_string(inst))
        return;
    if (regexec(&r->re, json_string_value(inst), 0, NULL, 0) != 0) {
        char got[96];
        render(inst, got, sizeof got);
        err(c, "pattern", "must match pattern \"%s\" (got %s)", json_string_value(v), got);
    }
}

/* ---- combinators */

static int schema_array(vctx *c, json_t *v, const char *kw)
{
    int ok = json_is_array(v) && json_array_size(v) > 0;
    size_t i;
    json_t *e;
    if (ok)
        json_array_foreach (v, i, e)
            if (!is_schema(e))
                ok = 0;
    if (!ok)
        err(c, "schema", "invalid schema: \"%s\" must be a non-empty array of schemas", kw);
    return ok;
}

KW(kw_allOf)
{
    if (!schema_array(c, v, "allOf"))
        return;
    size_t i;
    json_t *e;
    json_array_foreach (v, i, e) {
        if (full(c))
            return;
        validate(c, e, inst);
    }
}

/* Collect {property: const value} of a branch: its "properties" with a
 * "const" (or one-value "enum"), through $ref and allOf. */
static void collect_consts(vctx *c, json_t *s, json_t *root, json_t *out, int depth)
{
    if (!json_is_object(s) || depth > 8)
        return;
    json_t *props = json_object_get(s, "properties");
    const char *k;
    json_t *p;
    if (json_is_object(props)) {
        json_object_foreach (props, k, p) {
            if (!json_is_object(p) || json_object_get(out, k))
                continue;
            json_t *cv = json_object_get(p, "const");
            json_t *ev = json_object_get(p, "enum");
            if (!cv && json_is_array(ev) && json_array_size(ev) == 1)
                cv = json_array_get(ev, 0);
            if (cv)
                json_object_set(out, k, cv);
        }
    }
    json_t *ref = json_object_get(s, "$ref");
    if (json_is_string(ref)) {
        json_t *nr = NULL;
        json_t *t = resolve_ref(c, json_string_value(ref), root, &nr, NULL, 0);
        if (t)
            collect_consts(c, t, nr, out, depth + 1);
    }
    json_t *all = json_object_get(s, "allOf");
    size_t i;
    json_t *e;
    if (json_is_array(all))
        json_array_foreach (all, i, e)
            collect_consts(c, e, root, out, depth + 1);
}

/* Does the branch's "type" (through $ref and allOf) accept the instance?
 * 1 yes, 0 no, -1 the branch does not say. */
static int branch_type_ok(vctx *c, json_t *s, json_t *root, json_t *inst, int depth)
{
    if (!json_is_object(s) || depth > 8)
        return -1;
    int res = -1;
    json_t *t = json_object_get(s, "type");
    if (json_is_string(t)) {
        res = type_matches(json_string_value(t), inst) == 1;
    } else if (json_is_array(t)) {
        size_t i;
        json_t *x;
        res = 0;
        json_array_foreach (t, i, x)
            if (json_is_string(x) && type_matches(json_string_value(x), inst) == 1)
                res = 1;
    }
    if (res == 0)
        return 0;
    json_t *ref = json_object_get(s, "$ref");
    if (json_is_string(ref)) {
        json_t *nr = NULL;
        json_t *target = resolve_ref(c, json_string_value(ref), root, &nr, NULL, 0);
        int r = target ? branch_type_ok(c, target, nr, inst, depth + 1) : -1;
        if (r == 0)
            return 0;
        if (r == 1)
            res = 1;
    }
    json_t *all = json_object_get(s, "allOf");
    size_t i;
    json_t *e;
    if (json_is_array(all)) {
        json_array_foreach (all, i, e) {
            int r = branch_type_ok(c, e, root, inst, depth + 1);
            if (r == 0)
                return 0;
            if (r == 1)
                res = 1;
        }
    }
    return res;
}

/* anyOf/oneOf matched nothing: if a discriminator-like const property selects
 * exactly one branch, report that branch's errors; otherwise one summary
 * error, naming the expected tag values when every branch has one. */
static void report_no_match(vctx *c, json_t *v, json_t *inst, const char *kw, const char *summary)
{
    size_t n = json_array_size(v);
    char suffix[256] = "";
    if (json_is_object(inst) && n <= 64) {
        json_t *maps[64];
        json_t *names = json_object();
        for (size_t b = 0; b < n; b++) {
            maps[b] = json_object();
            collect_consts(c, json_array_get(v, b), c->root, maps[b], 0);
            const char *k;
            json_t *cv;
            json_object_foreach (maps[b], k, cv)
                json_object_set(names, k, json_true());
        }
        const char *k;
        json_t *unused;
        long chosen = -1;
        const char *tag_all = NULL; /* a property every branch has a const for */
        json_object_foreach (names, k, unused) {
            json_t *iv = json_object_get(inst, k);
            size_t nconst = 0, nmatch = 0, which = 0;
            for (size_t b = 0; b < n; b++) {
                json_t *cv = json_object_get(maps[b], k);
                if (!cv)
                    continue;
                nconst++;
                if (iv && values_equal(cv, iv)) {
                    nmatch++;
                    which = b;
                }
            }
            if (iv && nmatch == 1) {
                chosen = (long)which;
                break;
            }
            if (nconst == n && nmatch == 0 && !tag_all)
                tag_all = k;
        }
        if (chosen < 0 && tag_all) {
            char list[160] = "", r[64];
            for (size_t b = 0; b < n; b++) {
                size_t l = strlen(list);
                render(json_object_get(maps[b], tag_all), r, sizeof r);
                if (l + strlen(r) + 8 >= sizeof list) {
                    snprintf(list + l, sizeof list - l, ", ...");
                    break;
                }
                snprintf(list + l, sizeof list - l, "%s%s", b ? ", " : "", r);
            }
            json_t *iv = json_object_get(inst, tag_all);
            if (iv) {
                char got[64];
                render(iv, got, sizeof got);
                snprintf(suffix, sizeof suffix, ": \"%s\" must be one of %s (got %s)", tag_all,
                         list, got);
            } else {
                snprintf(suffix, sizeof suffix, ": missing \"%s\" (one of %s)", tag_all, list);
            }
        }
        for (size_t b = 0; b < n; b++)
            json_decref(maps[b]);
        json_decref(names);
        if (chosen >= 0) {
            size_t before = c->added;
            validate(c, json_array_get(v, (size_t)chosen), inst);
            if (c->added > before)
                return;
        }
    }
    /* No tag: if the branches declare types and exactly one accepts the
     * instance's type, that branch's errors are the useful ones. */
    if (n > 1 && !*suffix) {
        size_t yes = 0, no = 0, which = 0;
        for (size_t b = 0; b < n; b++) {
            int r = branch_type_ok(c, json_array_get(v, b), c->root, inst, 0);
            if (r == 1) {
                yes++;
                which = b;
            } else if (r == 0) {
                no++;
            }
        }
        if (yes == 1 && no == n - 1) {
            size_t before = c->added;
            validate(c, json_array_get(v, which), inst);
            if (c->added > before)
                return;
        }
    }
    err(c, kw, "%s%s", summary, suffix);
}

KW(kw_anyOf)
{
    if (!schema_array(c, v, "anyOf"))
        return;
    size_t i;
    json_t *e;
    json_array_foreach (v, i, e)
        if (!trial(c, e, inst))
            return;
    /* anyOf of bare {"required": [...]} branches ("give phi or count"):
     * name the alternatives instead of counting them. */
    char alts[200] = "";
    int only_required = 1;
    json_array_foreach (v, i, e) {
        json_t *req = json_object_get(e, "required");
        if (!json_is_object(e) || json_object_size(e) != 1 || !json_is_array(req)) {
            only_required = 0;
            break;
        }
        size_t k;
        json_t *name;
        size_t len = strlen(alts);
        snprintf(alts + len, sizeof alts - len, "%s", i ? " or " : "");
        json_array_foreach (req, k, name) {
            len = strlen(alts);
            snprintf(alts + len, sizeof alts - len, "%s\"%s\"", k ? "+" : "",
                     json_is_string(name) ? json_string_value(name) : "?");
        }
    }
    if (only_required && json_is_object(inst)) {
        err(c, "anyOf", "needs %s", alts);
        return;
    }
    char summary[96];
    snprintf(summary, sizeof summary, "must match at least one of %zu alternatives (matched 0)",
             json_array_size(v));
    report_no_match(c, v, inst, "anyOf", summary);
}

KW(kw_oneOf)
{
    if (!schema_array(c, v, "oneOf"))
        return;
    size_t i, matched = 0;
    json_t *e;
    json_array_foreach (v, i, e)
        if (!trial(c, e, inst))
            matched++;
    if (matched == 1)
        return;
    char summary[96];
    snprintf(summary, sizeof summary, "must match exactly one of %zu alternatives (matched %zu)",
             json_array_size(v), matched);
    if (matched == 0)
        report_no_match(c, v, inst, "oneOf", summary);
    else
        err(c, "oneOf", "%s", summary);
}

KW(kw_not)
{
    if (!is_schema(v)) {
        err(c, "schema", "invalid schema: \"not\" must be a schema");
        return;
    }
    if (!trial(c, v, inst))
        err(c, "not", "must not match the schema in \"not\"");
}

KW(kw_if)
{
    json_t *then_s = json_object_get(s, "then"), *else_s = json_object_get(s, "else");
    if (!is_schema(v) || (then_s && !is_schema(then_s)) || (else_s && !is_schema(else_s))) {
        err(c, "schema", "invalid schema: \"if\"/\"then\"/\"else\" must be schemas");
        return;
    }
    json_t *branch = trial(c, v, inst) ? else_s : then_s;
    if (branch)
        validate(c, branch, inst);
}

KW(kw_defs)
{
    if (!json_is_object(v))
        err(c, "schema", "invalid schema: \"$defs\" must be an object");
}

KW(kw_ignore) {}

typedef void (*kw_fn)(vctx *, json_t *, json_t *, json_t *);

static const struct {
    const char *name;
    kw_fn fn;
} keywords[] = {
    {"$ref", kw_ref},
    {"type", kw_type},
    {"enum", kw_enum},
    {"const", kw_const},
    {"properties", kw_properties},
    {"required", kw_required},
    {"additionalProperties", kw_additional},
    {"minProperties", kw_minProperties},
    {"maxProperties", kw_maxProperties},
    {"dependentRequired", kw_dependentRequired},
    {"items", kw_items},
    {"prefixItems", kw_prefixItems},
    {"minItems", kw_minItems},
    {"maxItems", kw_maxItems},
    {"uniqueItems", kw_uniqueItems},
    {"minimum", kw_minimum},
    {"maximum", kw_maximum},
    {"exclusiveMinimum", kw_exclusiveMinimum},
    {"exclusiveMaximum", kw_exclusiveMaximum},
    {"multipleOf", kw_multipleOf},
    {"minLength", kw_minLength},
    {"maxLength", kw_maxLength},
    {"pattern", kw_pattern},
    {"allOf", kw_allOf},
    {"anyOf", kw_anyOf},
    {"oneOf", kw_oneOf},
    {"not", kw_not},
    {"if", kw_if},
    {"then", kw_ignore}, /* evaluated by "if" */
    {"else", kw_ignore},
    {"$defs", kw_defs},
    {"definitions", kw_ignore},
    /* annotations and identifiers: no assertion */
    {"$schema", kw_ignore},
    {"$id", kw_ignore},
    {"$comment", kw_ignore},
    {"$anchor", kw_ignore},
    {"$vocabulary", kw_ignore},
    {"title", kw_ignore},
    {"description", kw_ignore},
    {"default", kw_ignore},
    {"examples", kw_ignore},
    {"deprecated", kw_ignore},
    {"readOnly", kw_ignore},
    {"writeOnly", kw_ignore},
    {"format", kw_ignore},
    {"contentMediaType", kw_ignore},
    {"contentEncoding", kw_ignore},
    {"unit", kw_ignore},
    {"units", kw_ignore},
};

static void validate(vctx *c, json_t *schema, json_t *inst)
{
    if (full(c))
        return;
    if (json_is_true(schema))
        return;
    if (json_is_false(schema)) {
        err(c, "false", "no value is allowed here");
        return;
    }
    if (!json_is_object(schema)) {
        err(c, "schema", "invalid schema: must be an object or boolean (got %s)",
            schema ? type_name(schema) : "nothing");
        return;
    }
    if (c->depth >= PK_SCHEMA_MAX_DEPTH) {
        err(c, "schema", "schema nesting deeper than %d levels (recursive schema?)",
            PK_SCHEMA_MAX_DEPTH);
        return;
    }
    c->depth++;
    const char *k;
    json_t *v;
    json_object_foreach (schema, k, v) {
        if (full(c))
            break;
        size_t i, nk = sizeof keywords / sizeof keywords[0];
        for (i = 0; i < nk; i++)
            if (!strcmp(keywords[i].name, k))
                break;
        if (i < nk)
            keywords[i].fn(c, schema, v, inst);
        else if (strncmp(k, "x-", 2) != 0) /* "x-..." are extension annotations */
            err(c, "schema", "invalid schema: unsupported keyword \"%s\"", k);
    }
    c->depth--;
}

size_t pk_schema_validate(json_t *schema, json_t *instance, pk_schema_loader loader,
                          void *loader_ctx, pk_schema_errors *errs)
{
    pk_schema_errors scratch = {0};
    vctx *c = calloc(1, sizeof *c);
    if (!c)
        return 0;
    c->root = schema;
    c->loader = loader;
    c->loader_ctx = loader_ctx;
    c->errs = errs ? errs : &scratch;
    c->limit = PK_SCHEMA_MAX_ERRORS;
    if (!instance)
        err(c, "schema", "no instance to validate");
    else
        validate(c, schema, instance);
    size_t added = c->added;
    while (c->res) {
        re_cache *r = c->res;
        c->res = r->next;
        if (r->ok)
            regfree(&r->re);
        free(r->pattern);
        free(r);
    }
    free(c);
    pk_schema_errors_free(&scratch);
    return added;
}

/* ------------------------------------------------------ embedded schemas */

static pthread_once_t embedded_once = PTHREAD_ONCE_INIT;
static json_t **embedded_parsed; /* parallel to pk_embedded_schemas[] */
static size_t embedded_count;

static void embedded_init(void)
{
    size_t n = 0;
    while (pk_embedded_schemas[n].name)
        n++;
    embedded_parsed = calloc(n ? n : 1, sizeof *embedded_parsed);
    if (!embedded_parsed)
        return;
    for (size_t i = 0; i < n; i++)
        embedded_parsed[i] =
            json_loadb(pk_embedded_schemas[i].text, pk_embedded_schemas[i].len, 0, NULL);
    embedded_count = n;
}

void pk_schema_errors_prefix(pk_schema_errors *e, size_t from, const char *prefix)
{
    const size_t np = strlen(prefix);
    for (size_t i = from; i < e->n; i++) {
        char *ptr = e->items[i].pointer;
        size_t len = strlen(ptr), cap = sizeof e->items[i].pointer;
        if (np >= cap)
            return;
        if (len + np + 1 > cap) /* a very deep pointer is cut at its end */
            len = cap - np - 1;
        memmove(ptr + np, ptr, len);
        memcpy(ptr, prefix, np);
        ptr[len + np] = 0;
    }
}

json_t *pk_schema_get(const char *schema_file)
{
    if (!schema_file)
        return NULL;
    pthread_once(&embedded_once, embedded_init);
    const char *base = strrchr(schema_file, '/');
    base = base ? base + 1 : schema_file;
    for (size_t i = 0; i < embedded_count; i++)
        if (!strcmp(pk_embedded_schemas[i].name, base))
            return embedded_parsed[i];
    return NULL;
}

static json_t *embedded_loader(const char *file, void *ctx)
{
    (void)ctx;
    return pk_schema_get(file);
}

size_t pk_schema_validate_embedded(const char *schema_file, json_t *instance,
                                   pk_schema_errors *errs)
{
    json_t *schema = pk_schema_get(schema_file);
    if (!schema) {
        pk_schema_errors_add(errs, "", "schema", "unknown or unparsable schema \"%s\"",
                             schema_file ? schema_file : "(null)");
        return 1;
    }
    return pk_schema_validate(schema, instance, embedded_loader, NULL, errs);
}
