/* test_http_problem.c — the problem table (api/http/http_problem.h): every
 * code has a status, a type and a title of its own row; an unknown code is
 * an internal error, never a crash. */
#include <string.h>

#include "api/http/http_problem.h"
#include "check.h"

static const char *member(json_t *d, const char *k)
{
    return json_string_value(json_object_get(d, k));
}

static void test_every_code_has_a_row(void)
{
    for (int c = 0; c < PK_P_COUNT; c++) {
        json_t *d = pk_problem_of((pk_problem_code)c, "x");
        unsigned st = pk_problem_status((pk_problem_code)c);
        CHECK_MSG(st >= 400 && st < 600, "code %d status %u", c, st);
        CHECK_MSG(member(d, "type") && member(d, "title") && *member(d, "title"), "code %d", c);
        CHECK(json_integer_value(json_object_get(d, "status")) == (json_int_t)st);
        CHECK(!strcmp(member(d, "detail"), "x"));
        json_decref(d);
    }
}

static void test_the_code_decides(void)
{
    json_t *d = pk_problem_of(PK_P_NO_SUCH_JOB, NULL);
    CHECK(pk_problem_status(PK_P_NO_SUCH_JOB) == 404 && !strcmp(member(d, "title"), "No such job"));
    CHECK(!strcmp(member(d, "type"), PK_PROBLEM_NO_SUCH_JOB) && !json_object_get(d, "detail"));
    json_decref(d);
    CHECK(pk_problem_status(PK_P_INTERNAL) == 500 && pk_problem_status(PK_P_COUNT) == 500);
    d = pk_problem_of(PK_P_COUNT, NULL);
    CHECK(json_integer_value(json_object_get(d, "status")) == 500);
    json_decref(d);
}

int main(void)
{
    RUN(test_every_code_has_a_row);
    RUN(test_the_code_decides);
    return check_summary();
}
