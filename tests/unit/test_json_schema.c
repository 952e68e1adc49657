/* test_json_schema.c — the JSON Schema validator (api/schemas/json_schema.c) and the
 * embedded schema table (api/schemas/schemas_embedded.c). */
#include "check.h"
#include "api/schemas/json_schema.h"
#include "api/schemas/schemas_embedded.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

static json_t *J(const char *text)
{
    json_error_t e;
    json_t *v = json_loads(text, JSON_DECODE_ANY, &e);
    if (!v) {
        fprintf(stderr, "bad test JSON (%s): %s\n", e.text, text);
        abort();
    }
    return v;
}

static void dump(const pk_schema_errors *e)
{
    for (size_t i = 0; i < e->n; i++)
        fprintf(stderr, "    [%s] %s: %s\n", e->items[i].pointer, e->items[i].rule,
                e->items[i].message);
}

/* Validate text against text (no loader); errors go to *e (freed first). */
static size_t V(pk_schema_errors *e, const char *schema, const char *inst)
{
    pk_schema_errors_free(e);
    json_t *s = J(schema), *i = J(inst);
    size_t n = pk_schema_validate(s, i, NULL, NULL, e);
    json_decref(s);
    json_decref(i);
    return n;
}

/* Is there an error at `ptr` with `rule` whose message contains `msg`
 * (NULL: any)? */
static int has(const pk_schema_errors *e, const char *ptr, const char *rule, const char *msg)
{
    for (size_t i = 0; i < e->n; i++)
        if (!strcmp(e->items[i].pointer, ptr) && !strcmp(e->items[i].rule, rule) &&
            (!msg || strstr(e->items[i].message, msg)))
            return 1;
    dump(e);
    return 0;
}

#define OK(schema, inst)                                                                           \
    do {                                                                                           \
        size_t n_ = V(&e, schema, inst);                                                           \
        CHECK_MSG(n_ == 0, "%s vs %s: %zu errors", schema, inst, n_);                              \
        if (n_)                                                                                    \
            dump(&e);                                                                              \
    } while (0)

#define BAD(schema, inst, ptr, rule, msg)                                                          \
    do {                                                                                           \
        size_t n_ = V(&e, schema, inst);                                                           \
        CHECK_MSG(n_ > 0, "%s vs %s: expected an error", schema, inst);                            \
        CHECK_MSG(has(&e, ptr, rule, msg), "%s vs %s: want [%s] %s ~ %s", schema, inst, ptr, rule, \
                  msg ? msg : "");                                                                 \
    } while (0)

static void test_type(void)
{
    pk_schema_errors e = {0};
    OK("{\"type\":\"integer\"}", "3");
    OK("{\"type\":\"integer\"}", "3.0"); /* 2020-12: integral reals are integers */
    BAD("{\"type\":\"integer\"}", "3.5", "", "type", "must be integer (got number 3.5)");
    BAD("{\"type\":\"integer\"}", "\"x\"", "", "type", "(got string \"x\")");
    OK("{\"type\":\"number\"}", "3");
    OK("{\"type\":\"number\"}", "-2.5");
    BAD("{\"type\":\"number\"}", "true", "", "type", "must be number (got boolean true)");
    OK("{\"type\":\"string\"}", "\"\"");
    OK("{\"type\":\"boolean\"}", "false");
    OK("{\"type\":\"null\"}", "null");
    BAD("{\"type\":\"null\"}", "0", "", "type", NULL);
    OK("{\"type\":\"object\"}", "{}");
    BAD("{\"type\":\"object\"}", "[]", "", "type", "must be object (got array)");
    OK("{\"type\":\"array\"}", "[]");
    OK("{\"type\":[\"integer\",\"null\"]}", "null");
    BAD("{\"type\":[\"integer\",\"null\"]}", "\"a\"", "", "type",
        "must be one of integer, null (got string \"a\")");
    pk_schema_errors_free(&e);
}

static void test_enum_const(void)
{
    pk_schema_errors e = {0};
    OK("{\"enum\":[2,3]}", "3");
    OK("{\"enum\":[2,3]}", "3.0");
    BAD("{\"enum\":[2,3]}", "4", "", "enum", "must be one of 2, 3 (got 4)");
    BAD("{\"enum\":[\"mm\",\"m\"]}", "\"km\"", "", "enum",
        "must be one of \"mm\", \"m\" (got \"km\")");
    OK("{\"enum\":[{\"a\":[1]}]}", "{\"a\":[1]}");
    OK("{\"const\":\"sieve\"}", "\"sieve\"");
    BAD("{\"const\":\"sieve\"}", "\"laser\"", "", "const", "must be \"sieve\" (got \"laser\")");
    BAD("{\"const\":null}", "0", "", "const", "must be null (got 0)");
    pk_schema_errors_free(&e);
}

static void test_properties_required(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"type\":\"object\",\"required\":[\"dim\",\"grading\"],"
                    "\"properties\":{\"dim\":{\"enum\":[2,3]},"
                    "\"box\":{\"type\":\"object\",\"required\":[\"size\"]}}}";
    OK(s, "{\"dim\":2,\"grading\":{}}");
    BAD(s, "{\"dim\":2}", "", "required", "missing required property \"grading\"");
    BAD(s, "{\"dim\":5,\"grading\":1}", "/dim", "enum", NULL);
    BAD(s, "{\"dim\":2,\"grading\":1,\"box\":{}}", "/box", "required",
        "missing required property \"size\"");
    OK("{\"required\":[\"a\"]}", "[1]"); /* object keywords ignore non-objects */
    CHECK(V(&e, s, "{}") == 2);
    pk_schema_errors_free(&e);
}

static void test_additional_properties(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"properties\":{\"a\":{},\"b\":{}},\"additionalProperties\":false}";
    OK(s, "{\"a\":1}");
    BAD(s, "{\"a\":1,\"bogus\":2}", "/bogus", "additionalProperties",
        "unknown property \"bogus\" (allowed: a, b)");
    BAD("{\"additionalProperties\":false}", "{\"x\":1}", "/x", "additionalProperties",
        "(allowed: none)");
    const char *s2 = "{\"properties\":{\"a\":{}},\"additionalProperties\":{\"type\":\"number\"}}";
    OK(s2, "{\"a\":\"s\",\"z\":1}");
    BAD(s2, "{\"a\":\"s\",\"z\":\"no\"}", "/z", "type", NULL);
    pk_schema_errors_free(&e);
}

static void test_pointer_escaping(void)
{
    pk_schema_errors e = {0};
    BAD("{\"additionalProperties\":false}", "{\"a/b~c\":1}", "/a~1b~0c", "additionalProperties",
        "unknown property \"a/b~c\"");
    BAD("{\"properties\":{\"x/y\":{\"properties\":{\"~\":{\"type\":\"string\"}}}}}",
        "{\"x/y\":{\"~\":1}}", "/x~1y/~0", "type", NULL);
    pk_schema_errors_free(&e);
}

static void test_nested_array_pointer(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"properties\":{\"grading\":{\"properties\":{\"sizes\":{\"type\":\"array\","
                    "\"items\":{\"type\":\"number\",\"exclusiveMinimum\":0}}}}}}";
    OK(s, "{\"grading\":{\"sizes\":[1,2,3.5]}}");
    BAD(s, "{\"grading\":{\"sizes\":[1,2,3,-1]}}", "/grading/sizes/3", "exclusiveMinimum",
        "must be > 0 (got -1)");
    CHECK(e.n == 1);
    pk_schema_errors_free(&e);
}

static void test_items_prefix_items(void)
{
    pk_schema_errors e = {0};
    const char *tuple = "{\"prefixItems\":[{\"type\":\"string\"},{\"type\":\"integer\"}],"
                        "\"items\":false}";
    OK(tuple, "[\"a\",1]");
    OK(tuple, "[\"a\"]");
    BAD(tuple, "[1,1]", "/0", "type", NULL);
    BAD(tuple, "[\"a\",1,true]", "/2", "items", "at most 2 items allowed (got 3)");
    const char *rest = "{\"prefixItems\":[{\"type\":\"string\"}],\"items\":{\"type\":\"integer\"}}";
    OK(rest, "[\"a\",1,2]");
    BAD(rest, "[\"a\",1,\"b\"]", "/2", "type", NULL);
    pk_schema_errors_free(&e);
}

static void test_min_max_items(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"minItems\":2,\"maxItems\":3}";
    OK(s, "[1,2]");
    OK(s, "[1,2,3]");
    BAD(s, "[1]", "", "minItems", "must have at least 2 items (got 1)");
    BAD(s, "[1,2,3,4]", "", "maxItems", "must have at most 3 items (got 4)");
    OK("{\"minItems\":2.0}", "[1,2]");
    pk_schema_errors_free(&e);
}

static void test_unique_items(void)
{
    pk_schema_errors e = {0};
    OK("{\"uniqueItems\":true}", "[1,2,\"1\",[1],{\"a\":1}]");
    OK("{\"uniqueItems\":false}", "[1,1]");
    BAD("{\"uniqueItems\":true}", "[1,2,2]", "/2", "uniqueItems", "duplicate of item 1");
    BAD("{\"uniqueItems\":true}", "[{\"a\":[1,2]},{\"a\":[1,2]}]", "/1", "uniqueItems", NULL);
    BAD("{\"uniqueItems\":true}", "[1,1.0]", "/1", "uniqueItems", NULL);
    pk_schema_errors_free(&e);
}

static void test_minimum_maximum(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"minimum\":0,\"maximum\":100}";
    OK(s, "0");
    OK(s, "100");
    OK(s, "99.5");
    OK(s, "\"not a number\"");
    BAD(s, "-1", "", "minimum", "must be >= 0 (got -1)");
    BAD(s, "100.25", "", "maximum", "must be <= 100 (got 100.25)");
    /* ints compare exactly beyond 2^53 */
    BAD("{\"maximum\":9007199254740992}", "9007199254740993", "", "maximum",
        "must be <= 9007199254740992 (got 9007199254740993)");
    OK("{\"minimum\":0.5}", "1");
    BAD("{\"minimum\":0.5}", "0", "", "minimum", "must be >= 0.5 (got 0)");
    pk_schema_errors_free(&e);
}

static void test_exclusive(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"properties\":{\"phi\":{\"properties\":{\"value\":{\"type\":\"number\","
                    "\"exclusiveMinimum\":0,\"exclusiveMaximum\":1}}}}}";
    OK(s, "{\"phi\":{\"value\":0.64}}");
    BAD(s, "{\"phi\":{\"value\":1.2}}", "/phi/value", "exclusiveMaximum", "must be < 1 (got 1.2)");
    BAD(s, "{\"phi\":{\"value\":1}}", "/phi/value", "exclusiveMaximum", "must be < 1 (got 1)");
    BAD(s, "{\"phi\":{\"value\":0}}", "/phi/value", "exclusiveMinimum", "must be > 0 (got 0)");
    pk_schema_errors_free(&e);
}

static void test_multiple_of(void)
{
    pk_schema_errors e = {0};
    OK("{\"multipleOf\":3}", "9");
    BAD("{\"multipleOf\":3}", "10", "", "multipleOf", "must be a multiple of 3 (got 10)");
    OK("{\"multipleOf\":0.1}", "0.3");
    OK("{\"multipleOf\":0.5}", "2");
    BAD("{\"multipleOf\":0.5}", "2.25", "", "multipleOf", "(got 2.25)");
    BAD("{\"multipleOf\":0}", "1", "", "schema", "multipleOf");
    pk_schema_errors_free(&e);
}

static void test_string_length(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"minLength\":2,\"maxLength\":3}";
    OK(s, "\"ab\"");
    OK(s, "\"\xc3\xa4\xc3\xb6\xc3\xbc\""); /* 3 code points, 6 bytes */
    BAD(s, "\"a\"", "", "minLength", "at least 2 characters long (got 1)");
    BAD(s, "\"abcd\"", "", "maxLength", "at most 3 characters long (got 4)");
    OK(s, "5");
    pk_schema_errors_free(&e);
}

static void test_pattern(void)
{
    pk_schema_errors e = {0};
    OK("{\"pattern\":\"^[A-C](8|16|32)$\"}", "\"B16\"");
    BAD("{\"pattern\":\"^[A-C](8|16|32)$\"}", "\"D16\"", "", "pattern",
        "must match pattern \"^[A-C](8|16|32)$\" (got \"D16\")");
    OK("{\"pattern\":\"es\"}", "\"test\""); /* unanchored, like ECMA */
    /* ECMA shorthand classes are translated to POSIX */
    OK("{\"pattern\":\"^\\\\d+\\\\s?[\\\\w-]*$\"}", "\"42 a_b-c\"");
    BAD("{\"pattern\":\"^\\\\d+$\"}", "\"ddd\"", "", "pattern", NULL);
    BAD("{\"pattern\":\"([a-z\"}", "\"x\"", "", "schema", "bad pattern");
    /* cached regex reused across many items */
    OK("{\"items\":{\"pattern\":\"^x\"}}", "[\"x1\",\"x2\",\"x3\"]");
    pk_schema_errors_free(&e);
}

static void test_min_max_properties(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"minProperties\":1,\"maxProperties\":2}";
    OK(s, "{\"a\":1}");
    BAD(s, "{}", "", "minProperties", "at least 1 properties (got 0)");
    BAD(s, "{\"a\":1,\"b\":2,\"c\":3}", "", "maxProperties", "at most 2 properties (got 3)");
    pk_schema_errors_free(&e);
}

static void test_all_of(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"allOf\":[{\"type\":\"integer\"},{\"minimum\":3},{\"maximum\":5}]}";
    OK(s, "4");
    BAD(s, "7", "", "maximum", NULL);
    CHECK(V(&e, s, "1.5") == 2); /* type and minimum */
    pk_schema_errors_free(&e);
}

static void test_any_of(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"anyOf\":[{\"required\":[\"phi\"]},{\"required\":[\"count\"]}]}";
    OK(s, "{\"phi\":1}");
    OK(s, "{\"phi\":1,\"count\":2}");
    /* bare "required" alternatives are named, not counted */
    BAD(s, "{}", "", "anyOf", "needs \"phi\" or \"count\"");
    CHECK(e.n == 1);
    const char *t = "{\"anyOf\":[{\"type\":\"string\"},{\"minimum\":3}]}";
    OK(t, "\"x\"");
    BAD(t, "1", "", "anyOf", "must match at least one of 2 alternatives (matched 0)");
    pk_schema_errors_free(&e);
}

static void test_one_of_generic(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"oneOf\":[{\"type\":\"boolean\"},"
                    "{\"type\":\"array\",\"items\":{\"type\":\"boolean\"}}]}";
    OK(s, "true");
    OK(s, "[true,false]");
    BAD(s, "3", "", "oneOf", "must match exactly one of 2 alternatives (matched 0)");
    CHECK(e.n == 1);
    BAD("{\"oneOf\":[{\"minimum\":0},{\"maximum\":10}]}", "5", "", "oneOf",
        "must match exactly one of 2 alternatives (matched 2)");
    /* only one branch accepts the instance's type: that branch's errors */
    BAD(s, "[true,1]", "/1", "type", "must be boolean (got integer 1)");
    CHECK(e.n == 1);
    pk_schema_errors_free(&e);
}

static const char *tagged =
    "{\"properties\":{\"grading\":{\"oneOf\":[{\"$ref\":\"#/$defs/sieve\"},"
    "{\"$ref\":\"#/$defs/fuller\"}]}},"
    "\"$defs\":{"
    "\"sieve\":{\"type\":\"object\",\"required\":[\"type\",\"sizes\"],"
    "\"additionalProperties\":false,\"properties\":{\"type\":{\"const\":\"sieve\"},"
    "\"sizes\":{\"type\":\"array\",\"items\":{\"type\":\"number\",\"exclusiveMinimum\":0}}}},"
    "\"fuller\":{\"type\":\"object\",\"required\":[\"type\",\"q\"],"
    "\"additionalProperties\":false,\"properties\":{\"type\":{\"const\":\"fuller\"},"
    "\"q\":{\"type\":\"number\",\"exclusiveMaximum\":1}}}}}";

static void test_one_of_discriminator(void)
{
    pk_schema_errors e = {0};
    OK(tagged, "{\"grading\":{\"type\":\"sieve\",\"sizes\":[1,2]}}");
    OK(tagged, "{\"grading\":{\"type\":\"fuller\",\"q\":0.5}}");
    /* the tag selects the branch: its errors, not "matches none" */
    BAD(tagged, "{\"grading\":{\"type\":\"sieve\",\"sizes\":[1,-2]}}", "/grading/sizes/1",
        "exclusiveMinimum", "must be > 0 (got -2)");
    CHECK(e.n == 1);
    BAD(tagged, "{\"grading\":{\"type\":\"fuller\",\"q\":0.5,\"extra\":1}}", "/grading/extra",
        "additionalProperties", NULL);
    BAD(tagged, "{\"grading\":{\"type\":\"fuller\"}}", "/grading", "required",
        "missing required property \"q\"");
    CHECK(e.n == 1);
    /* unknown or missing tag: one summary naming the tags */
    BAD(tagged, "{\"grading\":{\"type\":\"laser\"}}", "/grading", "oneOf",
        "must match exactly one of 2 alternatives (matched 0): \"type\" must be one of "
        "\"sieve\", \"fuller\" (got \"laser\")");
    CHECK(e.n == 1);
    BAD(tagged, "{\"grading\":{\"q\":0.5}}", "/grading", "oneOf",
        "missing \"type\" (one of \"sieve\", \"fuller\")");
    pk_schema_errors_free(&e);
}

static void test_not(void)
{
    pk_schema_errors e = {0};
    OK("{\"not\":{\"type\":\"string\"}}", "1");
    BAD("{\"not\":{\"type\":\"string\"}}", "\"s\"", "", "not", "must not match");
    pk_schema_errors_free(&e);
}

static void test_if_then_else(void)
{
    pk_schema_errors e = {0};
    const char *s =
        "{\"if\":{\"properties\":{\"kind\":{\"const\":\"mass\"}},\"required\":[\"kind\"]},"
        "\"then\":{\"required\":[\"density\"]},\"else\":{\"required\":[\"volume\"]}}";
    OK(s, "{\"kind\":\"mass\",\"density\":2.65}");
    OK(s, "{\"kind\":\"vol\",\"volume\":1}");
    BAD(s, "{\"kind\":\"mass\"}", "", "required", "\"density\"");
    BAD(s, "{\"kind\":\"vol\"}", "", "required", "\"volume\"");
    OK("{\"if\":{\"type\":\"string\"},\"then\":{\"minLength\":2}}", "5");
    pk_schema_errors_free(&e);
}

static void test_dependent_required(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"dependentRequired\":{\"mass_percent\":[\"density\"]}}";
    OK(s, "{}");
    OK(s, "{\"mass_percent\":5,\"density\":2.6}");
    BAD(s, "{\"mass_percent\":5}", "", "dependentRequired",
        "property \"mass_percent\" requires property \"density\"");
    pk_schema_errors_free(&e);
}

static void test_ref_local(void)
{
    pk_schema_errors e = {0};
    const char *s = "{\"properties\":{\"d\":{\"$ref\":\"#/$defs/length\"},"
                    "\"e\":{\"$ref\":\"#/$defs/a~1b%25\"},\"f\":{\"$ref\":\"#/$defs/list/1\"}},"
                    "\"$defs\":{\"length\":{\"type\":\"number\",\"exclusiveMinimum\":0},"
                    "\"a/b%\":{\"type\":\"string\"},\"list\":[true,{\"const\":7}]}}";
    OK(s, "{\"d\":1,\"e\":\"x\",\"f\":7}");
    BAD(s, "{\"d\":0}", "/d", "exclusiveMinimum", NULL);
    BAD(s, "{\"e\":1}", "/e", "type", NULL);
    BAD(s, "{\"f\":8}", "/f", "const", NULL);
    BAD("{\"$ref\":\"#/$defs/nope\"}", "1", "", "schema", "cannot resolve $ref \"#/$defs/nope\"");
    BAD("{\"$ref\":\"other.json#/x\"}", "1", "", "schema", "no loader");
    /* $ref with sibling keywords: both apply (2020-12) */
    BAD("{\"$ref\":\"#/$defs/n\",\"maximum\":3,\"$defs\":{\"n\":{\"type\":\"number\"}}}", "4", "",
        "maximum", NULL);
    pk_schema_errors_free(&e);
}

static json_t *other_doc;
static int loader_calls;
static json_t *test_loader(const char *file, void *ctx)
{
    loader_calls++;
    CHECK(ctx == (void *)&other_doc);
    return strcmp(file, "common.schema.json") == 0 ? other_doc : NULL;
}

static void test_ref_loader(void)
{
    pk_schema_errors e = {0};
    /* the local ref inside common.schema.json resolves within that file */
    other_doc = J("{\"$defs\":{\"length\":{\"$ref\":\"#/$defs/pos\"},"
                  "\"pos\":{\"type\":\"number\",\"exclusiveMinimum\":0}}}");
    json_t *s = J("{\"properties\":{\"d\":{\"$ref\":\"common.schema.json#/$defs/length\"},"
                  "\"u\":{\"$ref\":\"./common.schema.json#/$defs/pos\"},"
                  "\"x\":{\"$ref\":\"missing.json#/a\"}},"
                  "\"$defs\":{\"pos\":{\"type\":\"string\"}}}");
    json_t *good = J("{\"d\":2.5,\"u\":1}"), *bad = J("{\"d\":-1}"), *miss = J("{\"x\":1}");
    CHECK(pk_schema_validate(s, good, test_loader, &other_doc, &e) == 0);
    CHECK(loader_calls > 0);
    CHECK(pk_schema_validate(s, bad, test_loader, &other_doc, &e) == 1);
    CHECK(has(&e, "/d", "exclusiveMinimum", "must be > 0 (got -1)"));
    pk_schema_errors_free(&e);
    CHECK(pk_schema_validate(s, miss, test_loader, &other_doc, &e) == 1);
    CHECK(has(&e, "/x", "schema", "unknown schema file \"missing.json\""));
    json_decref(good);
    json_decref(bad);
    json_decref(miss);
    json_decref(s);
    json_decref(other_doc);
    pk_schema_errors_free(&e);
}

static void test_ref_cycles(void)
{
    pk_schema_errors e = {0};
    BAD("{\"$ref\":\"#\"}", "1", "", "schema", "circular $ref");
    BAD("{\"$ref\":\"#/$defs/a\",\"$defs\":{\"a\":{\"$ref\":\"#/$defs/b\"},"
        "\"b\":{\"allOf\":[{\"$ref\":\"#/$defs/a\"}]}}}",
        "{}", "", "schema", "circular $ref");
    BAD("{\"oneOf\":[{\"$ref\":\"#\"},{\"type\":\"string\"}]}", "1", "", "schema", "circular");
    /* a legitimately recursive schema works ... */
    const char *tree = "{\"type\":\"object\",\"properties\":{\"kid\":{\"$ref\":\"#\"},"
                       "\"v\":{\"type\":\"integer\"}}}";
    OK(tree, "{\"kid\":{\"kid\":{\"v\":1}}}");
    BAD(tree, "{\"kid\":{\"kid\":{\"v\":\"x\"}}}", "/kid/kid/v", "type", NULL);
    /* ... and stops at the depth limit on absurdly deep input */
    char deep[4096] = "";
    for (int i = 0; i < 200; i++)
        strcat(deep, "{\"kid\":");
    strcat(deep, "{}");
    for (int i = 0; i < 200; i++)
        strcat(deep, "}");
    CHECK(V(&e, tree, deep) >= 1);
    CHECK(e.n >= 1 && strcmp(e.items[0].rule, "schema") == 0 &&
          strstr(e.items[0].message, "deeper than"));
    pk_schema_errors_free(&e);
}

static void test_malformed_schema(void)
{
    pk_schema_errors e = {0};
    BAD("{\"minimum\":\"3\"}", "1", "", "schema", "\"minimum\" must be a number");
    BAD("{\"type\":\"float\"}", "1", "", "schema", "unknown type \"float\"");
    BAD("{\"type\":7}", "1", "", "schema", NULL);
    BAD("{\"required\":\"a\"}", "{}", "", "schema", NULL);
    BAD("{\"properties\":[]}", "{}", "", "schema", NULL);
    BAD("{\"items\":3}", "[1]", "", "schema", NULL);
    BAD("{\"oneOf\":[]}", "1", "", "schema", NULL);
    BAD("{\"allOf\":[1]}", "1", "", "schema", NULL);
    BAD("{\"minLength\":-1}", "\"\"", "", "schema", NULL);
    BAD("{\"dependentRequired\":{\"a\":[1]}}", "{}", "", "schema", NULL);
    BAD("[]", "1", "", "schema", "must be an object or boolean");
    BAD("{\"properties\":{\"a\":5}}", "{\"a\":1}", "/a", "schema", NULL);
    /* unknown assertion keywords are schema bugs; annotations are not */
    BAD("{\"contains\":{}}", "[1]", "", "schema", "unsupported keyword \"contains\"");
    OK("{\"title\":\"t\",\"description\":\"d\",\"default\":1,\"unit\":\"mm\",\"format\":\"x\","
       "\"$comment\":\"c\",\"examples\":[1],\"x-ui\":{}}",
       "1");
    /* a schema bug inside a "not"/"anyOf" branch is reported, never swallowed */
    BAD("{\"not\":{\"maximum\":\"x\"}}", "1", "", "schema", NULL);
    BAD("{\"anyOf\":[{\"type\":\"strin\"},{\"type\":\"integer\"}]}", "1", "", "schema", NULL);
    /* false schema */
    BAD("{\"properties\":{\"a\":false}}", "{\"a\":1}", "/a", "false", NULL);
    /* NULL arguments do not crash */
    CHECK(pk_schema_validate(NULL, NULL, NULL, NULL, &e) >= 1);
    json_t *one = json_integer(1);
    CHECK(pk_schema_validate(NULL, one, NULL, NULL, NULL) == 1);
    json_decref(one);
    pk_schema_errors_free(&e);
}

static void test_max_errors(void)
{
    pk_schema_errors e = {0};
    json_t *s = J("{\"items\":{\"type\":\"string\"}}");
    json_t *a = json_array();
    for (int i = 0; i < 500; i++)
        json_array_append_new(a, json_integer(i));
    pk_schema_errors_add(&e, "/pre", "semantic", "existing %d", 1);
    size_t n = pk_schema_validate(s, a, NULL, NULL, &e);
    CHECK(n == PK_SCHEMA_MAX_ERRORS);
    CHECK(e.n == PK_SCHEMA_MAX_ERRORS + 1);
    CHECK(!strcmp(e.items[0].pointer, "/pre") && !strcmp(e.items[0].message, "existing 1"));
    CHECK(!strcmp(e.items[1].pointer, "/0") && !strcmp(e.items[100].pointer, "/99"));
    json_decref(s);
    json_decref(a);
    pk_schema_errors_free(&e);
    CHECK(e.n == 0 && e.items == NULL);
}

static void test_errors_json(void)
{
    pk_schema_errors e = {0};
    char longkey[600];
    memset(longkey, 'k', sizeof longkey - 1);
    longkey[sizeof longkey - 1] = '\0';
    pk_schema_errors_add(&e, "/phi/value", "exclusiveMaximum", "must be < %d (got %.1f)", 1, 1.2);
    pk_schema_errors_add(&e, longkey, longkey, "%s", longkey); /* truncated, not overflowed */
    json_t *j = pk_schema_errors_json(&e);
    CHECK(json_array_size(j) == 2);
    json_t *x = json_array_get(j, 0);
    CHECK(!strcmp(json_string_value(json_object_get(x, "pointer")), "/phi/value"));
    CHECK(!strcmp(json_string_value(json_object_get(x, "rule")), "exclusiveMaximum"));
    CHECK(!strcmp(json_string_value(json_object_get(x, "message")), "must be < 1 (got 1.2)"));
    CHECK(strlen(e.items[1].pointer) == 255 && strlen(e.items[1].rule) == 31);
    json_decref(j);
    pk_schema_errors_free(&e);
}

static void *get_all(void *arg)
{
    (void)arg;
    for (const pk_embedded_schema *s = pk_embedded_schemas; s->name; s++)
        if (!pk_schema_get(s->name))
            return (void *)s->name;
    return NULL;
}

static void test_embedded(void)
{
    pthread_t th[4];
    for (int i = 0; i < 4; i++)
        pthread_create(&th[i], NULL, get_all, NULL);
    for (int i = 0; i < 4; i++) {
        void *r;
        pthread_join(th[i], &r);
        CHECK_MSG(r == NULL, "embedded schema %s does not parse", (const char *)r);
    }
    for (const pk_embedded_schema *s = pk_embedded_schemas; s->name; s++) {
        CHECK(pk_schema_text(s->name) == s->text);
        CHECK(strlen(s->text) == s->len);
        json_t *a = pk_schema_get(s->name);
        CHECK(a && a == pk_schema_get(s->name)); /* parsed once, cached */
        if (!json_object_get(a, "$schema")) /* not a JSON Schema: e.g. openapi.json, served as is */
            continue;
        /* whatever the instance, no embedded schema may report a schema bug */
        const char *insts[] = {"{}", "[]", "1", "\"x\"", "null", "{\"type\":\"sieve\"}"};
        for (size_t i = 0; i < sizeof insts / sizeof insts[0]; i++) {
            pk_schema_errors e = {0};
            json_t *in = J(insts[i]);
            pk_schema_validate_embedded(s->name, in, &e);
            for (size_t k = 0; k < e.n; k++)
                CHECK_MSG(strcmp(e.items[k].rule, "schema") != 0, "%s: %s", s->name,
                          e.items[k].message);
            json_decref(in);
            pk_schema_errors_free(&e);
        }
    }
    CHECK(pk_schema_text("no-such.schema.json") == NULL);
    CHECK(pk_schema_get("no-such.schema.json") == NULL);
    pk_schema_errors e = {0};
    json_t *in = json_object();
    CHECK(pk_schema_validate_embedded("no-such.schema.json", in, &e) == 1);
    CHECK(has(&e, "", "schema", "no-such.schema.json"));
    json_decref(in);
    pk_schema_errors_free(&e);
}

/* Every "type": "integer" of every embedded JSON Schema, at any depth, and
 * every number of a schema that a process reads as an integer has a
 * "maximum" (issue 21: "count": 1e308 was an integer to the schema and 0 to
 * the reader); pk_json_int reads integral decimals exactly. */
static void integer_maxima(json_t *s, const char *name, const char *at, int *n)
{
    if (json_is_array(s)) {
        size_t i;
        json_t *v;
        json_array_foreach (s, i, v)
            integer_maxima(v, name, at, n);
        return;
    }
    if (!json_is_object(s))
        return;
    const char *t = json_string_value(json_object_get(s, "type"));
    if (t && !strcmp(t, "integer")) {
        (*n)++;
        CHECK_MSG(json_is_number(json_object_get(s, "maximum")), "%s: integer at %s has no maximum",
                  name, at);
    }
    const char *k;
    json_t *v;
    json_object_foreach (s, k, v) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s/%s", at, k);
        integer_maxima(v, name, sub, n);
    }
}

static void test_integer_fields(void)
{
    int n = 0;
    for (const pk_embedded_schema *s = pk_embedded_schemas; s->name; s++) {
        json_t *a = pk_schema_get(s->name);
        if (json_object_get(a, "$schema"))
            integer_maxima(a, s->name, "", &n);
    }
    CHECK(n >= 20);
    long long v = -1;
    json_t *x = J("500.0");
    CHECK(pk_json_int(x, &v) == 0 && v == 500);
    json_decref(x);
    x = J("500");
    CHECK(pk_json_int(x, &v) == 0 && v == 500);
    json_decref(x);
    x = J("-0.0");
    CHECK(pk_json_int(x, &v) == 0 && v == 0);
    json_decref(x);
    const char *bad[] = {"2.5", "1e308", "9007199254740994.0", "\"5\"", "true", "null"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        x = J(bad[i]);
        CHECK_MSG(pk_json_int(x, &v) != 0, "%s read as an integer", bad[i]);
        json_decref(x);
    }
}

/* One rewrite of error pointers (the job file's and the request body's
 * /inputs): from the mark on, a deep pointer cut at its end, never overflowing. */
static void test_errors_prefix(void)
{
    pk_schema_errors e = {0};
    pk_schema_errors_add(&e, "/dim", "type", "x");
    pk_schema_errors_add(&e, "/phi/value", "minimum", "x");
    pk_schema_errors_add(&e, "", "required", "x");
    char deep[300];
    memset(deep, 'a', sizeof deep - 1);
    deep[0] = '/';
    deep[sizeof deep - 1] = 0;
    pk_schema_errors_add(&e, deep, "type", "x");
    pk_schema_errors_prefix(&e, 1, "/inputs");
    CHECK(!strcmp(e.items[0].pointer, "/dim")); /* before the mark: untouched */
    CHECK(!strcmp(e.items[1].pointer, "/inputs/phi/value"));
    CHECK(!strcmp(e.items[2].pointer, "/inputs"));
    size_t n = strlen(e.items[3].pointer);
    CHECK(n == sizeof e.items[3].pointer - 1 && !strncmp(e.items[3].pointer, "/inputs/aaa", 11));
    pk_schema_errors_free(&e);
}

int main(void)
{
    RUN(test_type);
    RUN(test_enum_const);
    RUN(test_properties_required);
    RUN(test_additional_properties);
    RUN(test_pointer_escaping);
    RUN(test_nested_array_pointer);
    RUN(test_items_prefix_items);
    RUN(test_min_max_items);
    RUN(test_unique_items);
    RUN(test_minimum_maximum);
    RUN(test_exclusive);
    RUN(test_multiple_of);
    RUN(test_string_length);
    RUN(test_pattern);
    RUN(test_min_max_properties);
    RUN(test_all_of);
    RUN(test_any_of);
    RUN(test_one_of_generic);
    RUN(test_one_of_discriminator);
    RUN(test_not);
    RUN(test_if_then_else);
    RUN(test_dependent_required);
    RUN(test_ref_local);
    RUN(test_ref_loader);
    RUN(test_ref_cycles);
    RUN(test_malformed_schema);
    RUN(test_max_errors);
    RUN(test_errors_json);
    RUN(test_errors_prefix);
    RUN(test_embedded);
    RUN(test_integer_fields);
    return check_summary();
}
