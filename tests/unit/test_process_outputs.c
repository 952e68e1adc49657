/* test_process_outputs.c — each process declares the outputs its results can
 * hold (api/http/http_outputs.h, pk_process.pictures): a pack job offers no
 * stress plot, a homogenization no grading curve; every picture kind is an
 * output pair, and the names a process lists are picture kinds. */
#include <stdio.h>
#include <string.h>

#include "api/http/http_outputs.h"
#include "api/http/http_process_doc.h"
#include "api/picture/picture.h"
#include "api/process.h"
#include "check.h"

static int declares(const char *process, const char *output)
{
    json_t *d = pk_process_description(pk_process_find(process));
    int has = json_object_get(json_object_get(d, "outputs"), output) != NULL;
    json_decref(d);
    return has;
}

static void test_declared_per_process(void)
{
    CHECK(declares("pack", "result") && declares("pack", "summary") && declares("pack", "xdmf"));
    CHECK(declares("pack", "grading.png") && declares("pack", "history.svg"));
    CHECK(!declares("pack", "stress.png") && !declares("pack", "residual.svg"));
    CHECK(!declares("pack", "response.png"));
    CHECK(declares("homogenize", "stress.png") && !declares("homogenize", "grading.png"));
    CHECK(!declares("homogenize", "history.png"));
    CHECK(declares("fe2", "response.svg") && !declares("fe2", "stress.png"));
    CHECK(declares("fe2", "field.png") && !declares("pack", "field.png"));
}

static void test_pictures_are_outputs(void)
{
    const char *name, *file;
    int k = 0;
    for (; (name = pk_picture_kind_name(k, &file, NULL, NULL)); k++) {
        char png[64], svg[64];
        snprintf(png, sizeof png, "%s.png", file);
        snprintf(svg, sizeof svg, "%s.svg", file);
        const pk_output *a = pk_output_find(png), *b = pk_output_find(svg);
        CHECK_MSG(a && b && a->picture && !strcmp(a->picture, name), "%s", name);
        CHECK(a && !strcmp(a->type, "image/png") && b && !strcmp(b->type, "image/svg+xml"));
    }
    CHECK(k >= 6);
    CHECK(pk_output_find("stress.gif") == NULL && pk_output_find(NULL) == NULL);
    char all[600];
    pk_outputs_list(all, sizeof all);
    CHECK_MSG(strstr(all, "summary, result, xdmf, field.png") && strstr(all, "picture.png") &&
                  strstr(all, "response.svg"),
              "%s", all);
    for (size_t i = 0; pk_processes[i]; i++)
        for (size_t j = 0; pk_processes[i]->pictures && pk_processes[i]->pictures[j]; j++) {
            pk_picture_kind kind;
            CHECK_MSG(pk_picture_kind_parse(pk_processes[i]->pictures[j], &kind) == 0, "%s: %s",
                      pk_processes[i]->id, pk_processes[i]->pictures[j]);
        }
}

int main(void)
{
    RUN(test_declared_per_process);
    RUN(test_pictures_are_outputs);
    return check_summary();
}
