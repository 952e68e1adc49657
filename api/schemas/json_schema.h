/* json_schema.h — one small JSON Schema (2020-12) validator, driven by the
 * schema files in schemas/ themselves: there is no second hand-written copy
 * of the rules.  It implements the keywords those files use:
 *   type, enum, const, properties, required, additionalProperties,
 *   items, prefixItems, minItems, maxItems, uniqueItems,
 *   minimum, maximum, exclusiveMinimum, exclusiveMaximum, multipleOf,
 *   minLength, maxLength, pattern (POSIX ERE), minProperties, maxProperties,
 *   allOf, anyOf, oneOf, not, if/then/else, dependentRequired,
 *   $ref (local "#/..." and "<file>#/..." to another embedded schema), $defs.
 * Annotation keywords (title, description, default, examples, $id, $schema,
 * $comment, format, unit...) are ignored.  An unknown *assertion* keyword is a
 * schema bug and is reported as such (rule "schema"), never silently passed.
 *
 * Each error names the instance location as a JSON pointer (RFC 6901, "" is
 * the root), the keyword that failed ("rule") and a human sentence. */
#ifndef PK_JSON_SCHEMA_H
#define PK_JSON_SCHEMA_H

#include <jansson.h>
#include <stddef.h>

/* Limits of one pk_schema_validate call: errors appended, and nesting of
 * subschema evaluation (guards against self-referential schemas). */
#define PK_SCHEMA_MAX_ERRORS 100
#define PK_SCHEMA_MAX_DEPTH 64

typedef struct pk_schema_error {
    char pointer[256]; /* e.g. "/grading/sizes/3" */
    char rule[32];     /* e.g. "minimum", "required", "type" */
    char message[256]; /* e.g. "must be >= 0 (got -1)" */
} pk_schema_error;

typedef struct pk_schema_errors {
    size_t n, cap;
    pk_schema_error *items;
} pk_schema_errors;

void pk_schema_errors_free(pk_schema_errors *e);
/* Append an error (printf-style message); used by the semantic checks in api/ too. */
/* Prefix the pointers of errors from..n with prefix ("/inputs": pointers of
 * the inputs made relative to the job file or the request body).  A pointer
 * that would overflow is cut at its end. */
void pk_schema_errors_prefix(pk_schema_errors *e, size_t from, const char *prefix);
void pk_schema_errors_add(pk_schema_errors *e, const char *pointer, const char *rule,
                          const char *fmt, ...) __attribute__((format(printf, 4, 5)));

/* Resolves "<file>" in "$ref": "<file>#/..." to a parsed schema; return a
 * borrowed reference (the loader keeps ownership) or NULL.  May be NULL: then
 * only local refs work. */
typedef json_t *(*pk_schema_loader)(const char *file, void *ctx);

/* Validate `instance` against `schema` (the root document for local refs).
 * Appends every error found (up to 100) to `errs`; returns the number appended.
 * Never crashes on malformed schemas: they yield rule "schema" errors. */
size_t pk_schema_validate(json_t *schema, json_t *instance, pk_schema_loader loader,
                          void *loader_ctx, pk_schema_errors *errs);

/* Convenience: validate against an embedded schema by file name (schemas/ base
 * name), using the embedded set to resolve cross-file refs. */
size_t pk_schema_validate_embedded(const char *schema_file, json_t *instance,
                                   pk_schema_errors *errs);

/* The embedded schema parsed once and cached (borrowed reference), or NULL. */
json_t *pk_schema_get(const char *schema_file);

/* An integer field as JSON Schema defines one ("type": "integer" accepts 500.0
 * and 1e3): a JSON integer, or a real with an integral value of magnitude
 * <= 2^53 (exactly representable).  0 with *out set, else -1 (fraction,
 * out of range, not a number).  Read every integer input through this:
 * jansson's json_integer_value reads 0 for a real. */
int pk_json_int(const json_t *v, long long *out);

/* Render the errors as a JSON array of {"pointer","rule","message"} (new ref). */
json_t *pk_schema_errors_json(const pk_schema_errors *e);

#endif
