/* http_process_doc.c — OGC process summaries and descriptions from the
 * process table and its embedded schemas (contract in http_process_doc.h). */
#include "http_process_doc.h"

#include <stdio.h>
#include <string.h>

#include "http_outputs.h"
#include "http_status_info.h"
#include "api/schemas/json_schema.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

json_t *pk_process_summary(const pk_process *p)
{
    char href[160];
    snprintf(href, sizeof href, "/processes/%s", p->id);
    char exec[180];
    snprintf(exec, sizeof exec, "/processes/%s/execution", p->id);
    /* sync-execute: Prefer: respond-sync waits up to sync_wait_s (docs/service.md) */
    return json_pack("{s:s,s:s,s:s,s:s,s:[s,s],s:[s,s],s:[{s:s,s:s,s:s},{s:s,s:s,s:s}]}", "id",
                     p->id, "title", p->title, "description", p->description, "version",
                     PACKD_VERSION, "jobControlOptions", "async-execute", "sync-execute",
                     "outputTransmission", "reference", "value", "links", "href", href, "rel",
                     "self", "type", "application/json", "href", exec, "rel",
                     "http://www.opengis.net/def/rel/ogc/1.0/execute", "type", "application/json");
}

/* Add to `into` every definition of `defs` that node refers to as
 * "#/$defs/<name>", and theirs in turn; and every other embedded schema
 * it refers to by file name, whole. */
static void collect_defs(json_t *node, json_t *defs, json_t *into)
{
    if (json_is_array(node)) {
        size_t i;
        json_t *e;
        json_array_foreach (node, i, e)
            collect_defs(e, defs, into);
        return;
    }
    const char *key;
    json_t *v;
    json_object_foreach (node, key, v) {
        const char *ref = json_string_value(v);
        char file[128];
        size_t flen = ref ? strcspn(ref, "#") : 0;
        if (!strcmp(key, "$ref") && ref && !strncmp(ref, "#/$defs/", 8)) {
            json_t *def = json_object_get(defs, ref + 8);
            if (def && !json_object_get(into, ref + 8)) {
                json_object_set(into, ref + 8, def);
                collect_defs(def, defs, into);
            }
        } else if (!strcmp(key, "$ref") && ref && flen && flen < sizeof file) {
            /* another embedded schema ("homogenize.inputs.schema.json#/…"):
             * bundled whole under its own "$id", where the reference finds it */
            snprintf(file, sizeof file, "%.*s", (int)flen, ref);
            json_t *doc = pk_schema_get(file);
            if (doc && !json_object_get(into, file)) {
                json_object_set(into, file, doc);
                collect_defs(doc, NULL, into); /* its own #/$defs stay inside it */
            }
        } else if (json_is_object(v) || json_is_array(v)) {
            collect_defs(v, defs, into);
        }
    }
}

/* An input's schema that a client can use alone: a copy carrying the $defs
 * its "#/$defs/…" references need, so they resolve with the input's schema
 * as the document root. */
static json_t *standalone_schema(json_t *ps, json_t *defs)
{
    json_t *need = json_object();
    collect_defs(ps, defs, need);
    json_t *out = json_deep_copy(ps);
    if (json_object_size(need))
        json_object_set(out, "$defs", need);
    json_decref(need);
    return out;
}

/* The process's whole inputs schema, self-contained: the other embedded
 * schemas it refers to by file name join its "$defs" whole, each under its
 * own "$id" (a JSON Schema 2020-12 compound document), where those
 * references resolve; its own definitions stay as they are. */
static json_t *bundled_schema(json_t *schema)
{
    json_t *defs = json_object_get(schema, "$defs");
    json_t *need = json_object();
    collect_defs(schema, defs, need);
    json_t *out = json_deep_copy(schema);
    if (defs)
        json_object_update_missing(need, defs);
    if (json_object_size(need))
        json_object_set(out, "$defs", need);
    json_decref(need);
    return out;
}

json_t *pk_process_description(const pk_process *p)
{
    json_t *d = pk_process_summary(p);
    json_t *schema = pk_schema_get(p->inputs_schema);
    json_t *props = json_object_get(schema, "properties");
    json_t *required = json_object_get(schema, "required");
    json_t *inputs = json_object();
    const char *name;
    json_t *ps;
    json_object_foreach (props, name, ps) {
        int req = 0;
        size_t i;
        json_t *r;
        json_array_foreach (required, i, r) {
            if (json_is_string(r) && !strcmp(json_string_value(r), name))
                req = 1;
        }
        json_t *in = json_pack("{s:s,s:i,s:i,s:o}", "title", name, "minOccurs", req, "maxOccurs", 1,
                               "schema", standalone_schema(ps, json_object_get(schema, "$defs")));
        json_t *desc = json_object_get(ps, "description");
        if (json_is_string(desc))
            json_object_set(in, "description", desc);
        json_object_set_new(inputs, name, in);
    }
    json_object_set_new(d, "inputs", inputs);
    json_t *outputs = json_object();
    const pk_output *o;
    for (size_t i = 0; (o = pk_output_at(i)); i++) {
        if (!pk_output_offered(p, o))
            continue;
        json_t *os = !strcmp(o->type, "application/json")
            ? json_pack("{s:s,s:s}", "type", "object", "contentMediaType", o->type)
            : json_pack("{s:s,s:s,s:s}", "type", "string", "contentEncoding",
                        strncmp(o->type, "image/svg", 9) && strcmp(o->type, "application/xml")
                            ? "binary"
                            : "8bit",
                        "contentMediaType", o->type);
        json_t *out = json_pack("{s:s,s:s,s:o}", "title", o->title, "description", o->description,
                                "schema", os);
        json_object_set_new(outputs, o->id, out);
    }
    json_object_set_new(d, "outputs", outputs);
    json_object_set_new(d, "inputsSchema", schema ? bundled_schema(schema) : json_null());
    return d;
}

static json_t *limit_schema(const pk_process *p, const char *name)
{
    json_t *s = json_object_get(pk_schema_get(p->inputs_schema), "properties");
    s = json_object_get(json_object_get(json_object_get(s, "limits"), "properties"), name);
    return s;
}

void pk_process_apply_caps(const pk_process *p, json_t *inputs, long max_particles,
                           double max_wall_time_s)
{
    if (!json_is_object(inputs))
        return;
    int has_np = limit_schema(p, "max_particles") != NULL;
    int has_wt = limit_schema(p, "wall_time_s") != NULL;
    if (!has_np && !has_wt)
        return;
    json_t *limits = json_object_get(inputs, "limits");
    if (!limits) {
        limits = json_object();
        json_object_set_new(inputs, "limits", limits);
    }
    if (!json_is_object(limits))
        return; /* the schema will say so */
    json_t *np = json_object_get(limits, "max_particles");
    long long np_v; /* 5e7 is an integer too (pk_json_int) */
    if (has_np && (!np || (pk_json_int(np, &np_v) == 0 && np_v > max_particles)))
        json_object_set_new(limits, "max_particles", json_integer(max_particles));
    json_t *wt = json_object_get(limits, "wall_time_s");
    if (has_wt && (!wt || (json_is_number(wt) && json_number_value(wt) > max_wall_time_s)))
        json_object_set_new(limits, "wall_time_s", json_real(max_wall_time_s));
}
