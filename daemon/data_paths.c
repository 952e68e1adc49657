/* data_paths.c — paths of the data directory rewritten for clients.
 * Contract: daemon/data_paths.h. */
#include "data_paths.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "daemon/store/job_files.h"

#define ID_LEN 36 /* a job id (uuid) */

/* A character that continues a file name. */
static int name_char(char c)
{
    return c && strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-+~", c);
}

/* The first occurrence of dir in s that is a whole path component, or NULL. */
static const char *find_dir(const char *s, const char *dir, size_t dl)
{
    for (const char *p = strstr(s, dir); p; p = strstr(p + 1, dir))
        if (!name_char(p[dl]) && (p == s || !name_char(p[-1]) || dir[0] == '/'))
            return p;
    return NULL;
}

static size_t id_len(const char *s)
{
    size_t n = strspn(s, "0123456789abcdef-");
    return n == ID_LEN && s[n] == '/' ? n : 0;
}

char *pk_hide_data_paths(const char *text, const char *data)
{
    char dir[1024];
    size_t dl = strlen(data);
    while (dl > 1 && data[dl - 1] == '/')
        dl--;
    if (!text || !dl || dl >= sizeof dir)
        return NULL;
    memcpy(dir, data, dl);
    dir[dl] = 0;
    const char *hit = find_dir(text, dir, dl);
    if (!hit)
        return NULL;
    char *out = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&out, &len);
    if (!f)
        return NULL;
    const char *p = text, *result = pk_job_file_name(PK_JOB_RESULT);
    size_t rl = strlen(result);
    for (; hit; hit = find_dir(p, dir, dl)) {
        fwrite(p, 1, (size_t)(hit - p), f);
        const char *q = hit + dl;
        if (!strncmp(q, "/files/", 7)) {
            fputs("/files/", f);
            p = q + 7;
        } else if (!strncmp(q, "/jobs/", 6) && id_len(q + 6)) {
            const char *name = q + 6 + ID_LEN + 1;
            if (!strncmp(name, result, rl) && !name_char(name[rl])) {
                fprintf(f, "/jobs/%.36s/results/result", q + 6);
                p = name + rl;
            } else {
                p = name;
            }
        } else {
            fputs("(data)", f);
            p = q;
        }
    }
    fputs(p, f);
    fclose(f);
    return out;
}

void pk_hide_data_paths_json(json_t *doc, const char *data)
{
    const char *key;
    json_t *v;
    size_t i;
    if (json_is_array(doc))
        json_array_foreach (doc, i, v)
            pk_hide_data_paths_json(v, data);
    void *tmp;
    json_object_foreach_safe (doc, tmp, key, v) {
        char *hidden = pk_hide_data_paths(json_string_value(v), data);
        if (hidden) {
            /* an input file of this service: the link it was given as */
            int link = !strcmp(key, "file") && json_object_size(doc) == 1 &&
                (!strncmp(hidden, "/files/", 7) || !strncmp(hidden, "/jobs/", 6));
            json_object_set_new(doc, link ? "href" : key, json_string(hidden));
            if (link)
                json_object_del(doc, "file");
            free(hidden);
        } else if (json_is_object(v) || json_is_array(v)) {
            pk_hide_data_paths_json(v, data);
        }
    }
    if (json_is_array(doc))
        for (i = 0; i < json_array_size(doc); i++) {
            char *hidden = pk_hide_data_paths(json_string_value(json_array_get(doc, i)), data);
            if (hidden) {
                json_array_set_new(doc, i, json_string(hidden));
                free(hidden);
            }
        }
}
