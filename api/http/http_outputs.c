/* http_outputs.c — the outputs table and the execute request's result
 * options (contract in http_outputs.h). */
#include "http_outputs.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "api/picture/picture.h"
#include "http_status_info.h"

/* The outputs every result has, then two per picture kind (picture.h). */
static const pk_output fixed[] = {
    {"summary", "application/json", "summary",
     "the worker's summary: counts, achieved density, grading, verdict, timings, result_digest", 0,
     NULL},
    {"result", PK_RESULT_MEDIA_TYPE, "result file",
     "HDF5 (H5MD 1.1) result file, see docs/result-format.md", 0, NULL},
    {"xdmf", "application/xml", "XDMF 3 description",
     "the grains as points with radius and species, for ParaView; refers to the result as "
     "<jobID>.h5",
     0, NULL},
};
#define NFIXED (sizeof fixed / sizeof *fixed)
#define MAX_OUTPUTS (NFIXED + 2 * 16)

static pk_output table[MAX_OUTPUTS + 1];
static char ids[MAX_OUTPUTS][40], svg_packing[200];
static pthread_once_t table_once = PTHREAD_ONCE_INIT;

static void table_init(void)
{
    size_t n = 0;
    for (; n < NFIXED; n++)
        table[n] = fixed[n];
    const char *name, *file, *title, *help;
    for (int k = 0; (name = pk_picture_kind_name(k, &file, &title, &help)) && n + 2 <= MAX_OUTPUTS;
         k++)
        for (int svg = 0; svg < 2; svg++, n++) {
            snprintf(ids[n], sizeof ids[n], "%s.%s", file, svg ? "svg" : "png");
            table[n] =
                (pk_output){ids[n], svg ? "image/svg+xml" : "image/png", title, help, 1, name};
            if (svg && !strcmp(file, "picture")) { /* one element per grain image */
                snprintf(svg_packing, sizeof svg_packing, "%s (up to %d grains)", help,
                         PK_PICTURE_SVG_MAX_GRAINS);
                table[n].description = svg_packing;
            }
        }
}

const pk_output *pk_output_at(size_t i)
{
    pthread_once(&table_once, table_init);
    return i < MAX_OUTPUTS && table[i].id ? &table[i] : NULL;
}

const pk_output *pk_output_find(const char *id)
{
    const pk_output *o;
    for (size_t i = 0; id && (o = pk_output_at(i)); i++)
        if (!strcmp(o->id, id))
            return o;
    return NULL;
}

int pk_output_offered(const pk_process *p, const pk_output *o)
{
    if (!o->picture)
        return 1;
    for (size_t i = 0; p->pictures && p->pictures[i]; i++)
        if (!strcmp(p->pictures[i], o->picture))
            return 1;
    return 0;
}

size_t pk_outputs_list(char *buf, size_t n)
{
    size_t k = 0;
    const pk_output *o;
    buf[0] = 0;
    for (size_t i = 0; (o = pk_output_at(i)) && k < n; i++)
        k += (size_t)snprintf(buf + k, n - k, "%s%s", i ? ", " : "", o->id);
    return k < n ? k : n - 1;
}

/* OGC API - Processes 1.0, "subscriber": where the job's events are POSTed. */
static int parse_subscriber(json_t *sub, pk_exec_opts *o, char *detail, size_t n)
{
    static const char *const uris[] = {"successUri", "inProgressUri", "failedUri"};
    if (!sub)
        return 0;
    if (!json_is_object(sub)) {
        snprintf(detail, n, "/subscriber: an object with successUri, inProgressUri, failedUri");
        return -1;
    }
    const char *key;
    json_t *v;
    json_object_foreach (sub, key, v) {
        size_t k = 0;
        while (k < 3 && strcmp(key, uris[k]))
            k++;
        const char *u = json_string_value(v);
        if (k == 3) {
            snprintf(detail, n, "/subscriber/%.60s: unknown (successUri, inProgressUri, failedUri)",
                     key);
            return -1;
        }
        size_t len = u ? strlen(u) : 0;
        int ok = len > 0 && len < 2048 &&
            (!strncasecmp(u, "http://", 7) || !strncasecmp(u, "https://", 8));
        for (size_t i = 0; ok && i < len; i++)
            ok = (unsigned char)u[i] > ' ' && (unsigned char)u[i] < 0x7f;
        if (!ok) {
            snprintf(detail, n, "/subscriber/%s: an absolute http or https URL (< 2048 bytes)",
                     key);
            return -1;
        }
    }
    o->subscriber = json_object_size(sub) ? json_incref(sub) : NULL;
    return 0;
}

int pk_exec_opts_parse(json_t *body, pk_exec_opts *o, char *detail, size_t n)
{
    memset(o, 0, sizeof *o);
    if (parse_subscriber(json_object_get(body, "subscriber"), o, detail, n) != 0)
        return -1;
    json_t *resp = json_object_get(body, "response");
    const char *mode = resp ? json_string_value(resp) : "document";
    if (!mode || (strcmp(mode, "raw") && strcmp(mode, "document"))) {
        snprintf(detail, n, "/response: \"raw\" or \"document\"");
        pk_exec_opts_free(o);
        return -1;
    }
    json_t *outs = json_object_get(body, "outputs");
    if (outs && !json_is_object(outs)) {
        snprintf(detail, n, "/outputs: an object whose keys are output ids");
        pk_exec_opts_free(o);
        return -1;
    }
    const char *key, *value_one = NULL;
    json_t *v;
    size_t values = 0;
    json_object_foreach (outs, key, v) {
        if (!pk_output_find(key)) {
            char all[600];
            pk_outputs_list(all, sizeof all);
            snprintf(detail, n, "/outputs/%.60s: no such output (%s)", key, all);
            pk_exec_opts_free(o);
            return -1;
        }
        json_t *tm = json_object_get(v, "transmissionMode");
        const char *t = tm ? json_string_value(tm) : "reference";
        if (!json_is_object(v) || !t || (strcmp(t, "value") && strcmp(t, "reference"))) {
            snprintf(detail, n, "/outputs/%.60s/transmissionMode: \"value\" or \"reference\"", key);
            pk_exec_opts_free(o);
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
    if (!o->serve[0] && !o->select && !o->subscriber)
        return NULL;
    json_t *j = json_object();
    if (o->serve[0])
        json_object_set_new(j, "serve", json_string(o->serve));
    if (o->select)
        json_object_set(j, "select", o->select);
    if (o->subscriber) {
        json_object_set(j, "subscriber", o->subscriber);
        json_object_set_new(j, "base", json_string(o->base));
    }
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
    json_t *sub = json_object_get(j, "subscriber");
    if (json_is_object(sub))
        o->subscriber = json_incref(sub);
    const char *base = json_string_value(json_object_get(j, "base"));
    snprintf(o->base, sizeof o->base, "%s", base ? base : "");
}

void pk_exec_opts_free(pk_exec_opts *o)
{
    json_decref(o->select);
    json_decref(o->subscriber);
    o->select = o->subscriber = NULL;
}
