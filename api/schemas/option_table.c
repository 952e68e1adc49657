/* option_table.c — the one filler of the option tables (JSON inputs → a job's
 * struct); the contract is in option_table.h. */
#include "option_table.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

json_t *pk_json_at(json_t *root, const char *pointer)
{
    json_t *v = root;
    const char *p = pointer;
    while (v && *p == '/') {
        const char *end = strchr(p + 1, '/');
        size_t n = end ? (size_t)(end - p - 1) : strlen(p + 1);
        char key[128];
        if (n >= sizeof key)
            return NULL;
        memcpy(key, p + 1, n);
        key[n] = 0;
        v = json_object_get(v, key);
        p += n + 1;
    }
    return v;
}

static void put_int(void *field, size_t size, long long x)
{
    if (size == sizeof(int)) {
        int i = (int)x;
        memcpy(field, &i, sizeof i);
    } else {
        memcpy(field, &x, sizeof x); /* long long, size_t, uint64_t: x >= 0 where unsigned */
    }
}

const char *const pk_quality_names[] = {"draft", "standard", "fine", NULL};

pk_quality pk_quality_of(json_t *root)
{
    const char *s = json_string_value(pk_json_at(root, "/quality"));
    for (int i = 0; s && pk_quality_names[i]; i++)
        if (!strcmp(pk_quality_names[i], s))
            return (pk_quality)i;
    return PK_QUALITY_STANDARD;
}

static void put_number(const pk_option *o, char *field, double x)
{
    switch (o->type) {
    case PK_OPT_NUMBER: memcpy(field, &x, sizeof x); break;
    case PK_OPT_INTEGER: put_int(field, o->size, (long long)x); break;
    case PK_OPT_BOOL:
    case PK_OPT_ENUM: put_int(field, sizeof(int), (long long)x); break;
    case PK_OPT_STRING: break;
    }
}

static void put_default(const pk_option *o, char *field)
{
    switch (o->type) {
    case PK_OPT_NUMBER:
    case PK_OPT_INTEGER:
    case PK_OPT_BOOL:
    case PK_OPT_ENUM: put_number(o, field, o->dflt); break;
    case PK_OPT_STRING: snprintf(field, o->size, "%s", o->sdefault ? o->sdefault : ""); break;
    }
}

static int enum_index(const char *const *names, const char *s)
{
    for (int i = 0; s && names[i]; i++)
        if (!strcmp(names[i], s))
            return i;
    return -1;
}

/* A present value into its field; -1 with an error naming the field. */
static int put_value(const pk_option *o, json_t *v, char *field, pk_schema_errors *errs)
{
    switch (o->type) {
    case PK_OPT_NUMBER: {
        if (!json_is_number(v))
            break;
        double x = json_number_value(v) + 0.0; /* + 0.0: no -0 in results or messages */
        memcpy(field, &x, sizeof x);
        return 0;
    }
    case PK_OPT_INTEGER: {
        long long x;
        if (pk_json_int(v, &x) != 0 || x < (long long)o->lo || x > (long long)o->hi) {
            char got[32];
            snprintf(got, sizeof got, "%.17g", json_number_value(v));
            pk_schema_errors_add(errs, o->pointer, "integer",
                                 "must be an integer in [%lld, %lld] (got %s)", (long long)o->lo,
                                 (long long)o->hi, got);
            return -1;
        }
        put_int(field, o->size, x);
        return 0;
    }
    case PK_OPT_BOOL:
        if (!json_is_boolean(v))
            break;
        put_int(field, sizeof(int), json_is_true(v));
        return 0;
    case PK_OPT_ENUM: {
        int i = enum_index(o->names, json_string_value(v));
        if (i < 0) {
            pk_schema_errors_add(errs, o->pointer, "enum", "is not one of the admitted values");
            return -1;
        }
        put_int(field, sizeof(int), i);
        return 0;
    }
    case PK_OPT_STRING: {
        const char *s = json_string_value(v);
        if (!s)
            break;
        if (strlen(s) >= o->size) {
            pk_schema_errors_add(errs, o->pointer, "maxLength", "at most %zu characters",
                                 o->size - 1);
            return -1;
        }
        memcpy(field, s, strlen(s) + 1);
        return 0;
    }
    }
    static const char *const kind[] = {"a number", "an integer", "a boolean", "a name", "a string"};
    pk_schema_errors_add(errs, o->pointer, "type", "must be %s", kind[o->type]);
    return -1;
}

size_t pk_options_fill(const pk_option_table *t, json_t *root, void *dst, pk_schema_errors *errs)
{
    size_t before = errs->n;
    const pk_quality q = pk_quality_of(root);
    if (t->preset)
        t->preset(dst);
    for (size_t i = 0; i < t->n; i++) {
        const pk_option *o = &t->rows[i];
        char *field = (char *)dst + o->off;
        json_t *v = pk_json_at(root, o->pointer);
        if (v && put_value(o, v, field, errs) == 0)
            continue;
        if (o->by_quality && q != PK_QUALITY_STANDARD)
            put_number(o, field, q == PK_QUALITY_DRAFT ? o->draft : o->fine);
        else if (o->how != PK_OPT_PRESET)
            put_default(o, field);
    }
    return errs->n - before;
}

json_t *pk_option_default_json(const pk_option *o, const void *filled)
{
    const char *field = (const char *)filled + o->off;
    if (o->how == PK_OPT_IMPLICIT)
        return NULL;
    switch (o->type) {
    case PK_OPT_NUMBER: {
        double x;
        memcpy(&x, field, sizeof x);
        return isnan(x) ? NULL : json_real(x);
    }
    case PK_OPT_INTEGER: {
        long long x = 0;
        if (o->size == sizeof(int)) {
            int i;
            memcpy(&i, field, sizeof i);
            x = i;
        } else
            memcpy(&x, field, sizeof x);
        return json_integer(x);
    }
    case PK_OPT_BOOL:
    case PK_OPT_ENUM: {
        int i;
        memcpy(&i, field, sizeof i);
        return o->type == PK_OPT_BOOL ? json_boolean(i) : json_string(o->names[i]);
    }
    case PK_OPT_STRING: return json_string(field);
    }
    return NULL;
}
