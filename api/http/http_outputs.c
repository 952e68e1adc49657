/* http_outputs.c — the outputs table and the execute request's result
 * options (contract in http_outputs.h). */
#include "http_outputs.h"

#include <stdio.h>
#include <string.h>

#include "http_status_info.h"

const pk_output pk_outputs[] = {
    {"summary", "application/json", "summary",
     "the worker's summary: counts, achieved density, grading, verdict, timings, result_digest", 0},
    {"result", PK_RESULT_MEDIA_TYPE, "result file",
     "HDF5 (H5MD 1.1) result file, see docs/result-format.md", 0},
    {"xdmf", "application/xml", "XDMF 3 description",
     "the grains as points with radius and species, for ParaView; refers to the result as "
     "<jobID>.h5",
     0},
    {"picture.png", "image/png", "the packing", "PNG picture of the packing", 1},
    {"picture.svg", "image/svg+xml", "the packing",
     "SVG picture of the packing (up to 20 000 grains)", 1},
    {"grading.png", "image/png", "the grading curve",
     "target and achieved grading curves (pack jobs)", 1},
    {"grading.svg", "image/svg+xml", "the grading curve",
     "target and achieved grading curves (pack jobs)", 1},
    {"history.png", "image/png", "the EDMD history",
     "phi and reduced pressure over the events (EDMD)", 1},
    {"history.svg", "image/svg+xml", "the EDMD history",
     "phi and reduced pressure over the events (EDMD)", 1},
    {"stress.png", "image/png", "the stress-strain curve", "P components over F (homogenize jobs)",
     1},
    {"stress.svg", "image/svg+xml", "the stress-strain curve",
     "P components over F (homogenize jobs)", 1},
    {"residual.png", "image/png", "the residual history",
     "relaxation residual of every load step (homogenize jobs)", 1},
    {"residual.svg", "image/svg+xml", "the residual history",
     "relaxation residual of every load step (homogenize jobs)", 1},
    {"response.png", "image/png", "the fe2 response",
     "reactions of the supports and dilatancy per load step (fe2 jobs)", 1},
    {"response.svg", "image/svg+xml", "the fe2 response",
     "reactions of the supports and dilatancy per load step (fe2 jobs)", 1},
    {NULL, NULL, NULL, NULL, 0},
};

const pk_output *pk_output_find(const char *id)
{
    for (const pk_output *o = pk_outputs; id && o->id; o++)
        if (!strcmp(o->id, id))
            return o;
    return NULL;
}

int pk_exec_opts_parse(json_t *body, pk_exec_opts *o, char *detail, size_t n)
{
    memset(o, 0, sizeof *o);
    json_t *resp = json_object_get(body, "response");
    const char *mode = resp ? json_string_value(resp) : "document";
    if (!mode || (strcmp(mode, "raw") && strcmp(mode, "document"))) {
        snprintf(detail, n, "/response: \"raw\" or \"document\"");
        return -1;
    }
    json_t *outs = json_object_get(body, "outputs");
    if (outs && !json_is_object(outs)) {
        snprintf(detail, n, "/outputs: an object whose keys are output ids");
        return -1;
    }
    const char *key, *value_one = NULL;
    json_t *v;
    size_t values = 0;
    json_object_foreach (outs, key, v) {
        if (!pk_output_find(key)) {
            snprintf(detail, n,
                     "/outputs/%.60s: no such output (summary, result, xdmf, "
                     "picture, grading, history, stress, residual, response .png/.svg)",
                     key);
            return -1;
        }
        json_t *tm = json_object_get(v, "transmissionMode");
        const char *t = tm ? json_string_value(tm) : "reference";
        if (!json_is_object(v) || !t || (strcmp(t, "value") && strcmp(t, "reference"))) {
            snprintf(detail, n, "/outputs/%.60s/transmissionMode: \"value\" or \"reference\"", key);
            return -1;
        }
        if (!strcmp(t, "value")) {
            values++;
            value_one = key;
        }
    }
    if (json_object_size(outs)) {
        o->select = json_array();
        json_object_foreach (outs, key, v)
            json_array_append_new(o->select, json_string(key));
    }
    if (!strcmp(mode, "raw")) {
        const char *one = "result";
        if (json_object_size(outs) == 1)
            json_object_foreach (outs, key, v)
                one = key;
        snprintf(o->serve, sizeof o->serve, "%s", one);
    } else if (json_object_size(outs) == 1 && values == 1) {
        snprintf(o->serve, sizeof o->serve, "%s", value_one);
    }
    return 0;
}

json_t *pk_exec_opts_json(const pk_exec_opts *o)
{
    if (!o->serve[0] && !o->select)
        return NULL;
    json_t *j = json_object();
    if (o->serve[0])
        json_object_set_new(j, "serve", json_string(o->serve));
    if (o->select)
        json_object_set(j, "select", o->select);
    return j;
}

void pk_exec_opts_from_json(json_t *j, pk_exec_opts *o)
{
    memset(o, 0, sizeof *o);
    const char *serve = json_string_value(json_object_get(j, "serve"));
    if (serve && pk_output_find(serve))
        snprintf(o->serve, sizeof o->serve, "%s", serve);
    json_t *sel = json_object_get(j, "select");
    if (json_is_array(sel))
        o->select = json_incref(sel);
}

void pk_exec_opts_free(pk_exec_opts *o)
{
    json_decref(o->select);
    o->select = NULL;
}
