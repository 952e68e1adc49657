/* option_table.h — declarative option tables: each input option of a process
 * or placer is one row (JSON pointer, type, destination field, default,
 * range), from which one filler fills the job's struct.  The schema keeps
 * the same defaults for its readers; tests/unit/test_option_tables.c holds
 * the two equal. */
#ifndef PK_OPTION_TABLE_H
#define PK_OPTION_TABLE_H

#include <jansson.h>
#include <stddef.h>

#include "json_schema.h"

typedef enum pk_opt_type {
    PK_OPT_NUMBER,  /* double; a -0 reads as +0 */
    PK_OPT_INTEGER, /* int, long long, size_t or uint64_t (by size), an exact integer in [lo, hi] */
    PK_OPT_BOOL,    /* int 0/1 */
    PK_OPT_ENUM,    /* int: the index of the value in names (an enum whose values follow names) */
    PK_OPT_STRING   /* char[size]; default sdefault */
} pk_opt_type;

typedef enum pk_opt_default {
    PK_OPT_GIVEN = 0, /* absent: dflt (sdefault), the schema's "default" */
    PK_OPT_IMPLICIT,  /* absent: dflt, whose meaning the code gives (e.g. 0 = the number of
                       * grains, NAN = chosen from the drawn sizes): no "default" in the schema */
    PK_OPT_PRESET     /* absent: the field keeps what the table's preset wrote (the engine's
                       * own default, e.g. pk_edmd_params_default); NAN there = implicit */
} pk_opt_default;

/* The job's "quality" (schemas: "draft" | "standard" | "fine"): which
 * default an absent option takes where its row has a quality column
 * (docs/presets.md).  "standard" is the row's own default. */
typedef enum pk_quality { PK_QUALITY_DRAFT, PK_QUALITY_STANDARD, PK_QUALITY_FINE } pk_quality;
extern const char *const pk_quality_names[]; /* in that order, NULL-terminated */

typedef struct pk_option {
    const char *pointer; /* JSON pointer from the object the table reads, "/edmd/skin" */
    pk_opt_type type;
    size_t off, size; /* destination field (PK_OPT_FIELD) */
    pk_opt_default how;
    double dflt;              /* NUMBER, INTEGER, BOOL (0/1), ENUM (index into names) */
    const char *sdefault;     /* STRING */
    double lo, hi;            /* INTEGER: the admitted range (the schema's minimum, maximum) */
    const char *const *names; /* ENUM: the values, NULL-terminated */
    int by_quality;           /* 1: absent, a draft / fine job takes draft / fine instead of
                               * the default (NUMBER, INTEGER, BOOL, ENUM index) */
    double draft, fine;
} pk_option;

/* The quality column of a row: PK_OPT_QUALITY(draft value, fine value). */
#define PK_OPT_QUALITY(d, f) .by_quality = 1, .draft = (d), .fine = (f)

typedef struct pk_option_table {
    const char *schema; /* the embedded schema the pointers live in */
    const pk_option *rows;
    size_t n;
    size_t size;               /* of the struct filled */
    void (*preset)(void *dst); /* or NULL: run before the rows (PK_OPT_PRESET rows keep it) */
} pk_option_table;

#define PK_OPT_FIELD(T, m) .off = offsetof(T, m), .size = sizeof(((T *)0)->m)
#define PK_OPT_TABLE(schema, T, rows, preset)                                                      \
    {                                                                                              \
        schema, rows, sizeof rows / sizeof *rows, sizeof(T), preset                                \
    }

/* The value at a JSON pointer ("/a/b", "" = root) of plain object keys, or NULL. */
json_t *pk_json_at(json_t *root, const char *pointer);

/* The quality root asks for ("/quality"; absent: standard). */
pk_quality pk_quality_of(json_t *root);

/* Fill dst from root (the object the pointers start from): preset, then
 * every row; an absent value takes the row's default, or its quality
 * column's value when root's "quality" is draft or fine (an explicit value
 * always wins).  A present value of
 * the wrong kind (an integer out of range, a name not in the enum) is an
 * error naming the field (the schema normally catches it first).  Returns
 * the number of errors appended. */
size_t pk_options_fill(const pk_option_table *t, json_t *root, void *dst, pk_schema_errors *errs);

/* The row's default as a JSON value (new reference), read from a struct the
 * table filled from an empty object (PK_OPT_PRESET: the preset's value); NULL
 * when the default is implicit. */
json_t *pk_option_default_json(const pk_option *row, const void *filled);

#endif
