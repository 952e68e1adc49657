/* html_lists.c — the HTML views of GET /processes and GET /jobs (html_page.h):
 * tables of what their JSON documents hold, each string escaped. */
#include <string.h>

#include "html_page.h"

static const char *str(json_t *o, const char *key)
{
    return json_string_value(json_object_get(o, key));
}

/* A table cell with a member's string as code (an id). */
static void code_cell(pk_html *h, json_t *o, const char *key)
{
    pk_html_raw(h, "<td><code>");
    pk_html_text(h, str(o, key));
    pk_html_raw(h, "</code></td>");
}

/* A table cell with each named member's value (escaped); keys end with NULL. */
static void cells(pk_html *h, json_t *o, const char *const *keys)
{
    for (; *keys; keys++) {
        pk_html_raw(h, "<td>");
        pk_html_value(h, json_object_get(o, *keys));
        pk_html_raw(h, "</td>");
    }
}

/* Every link of o as "<a>title or rel</a>", separated by blanks. */
static void links_cell(pk_html *h, json_t *o)
{
    pk_html_raw(h, "<td>");
    size_t i;
    json_t *l;
    json_array_foreach (json_object_get(o, "links"), i, l) {
        const char *href = str(l, "href"), *rel = str(l, "rel");
        if (!href)
            continue;
        const char *slash = rel ? strrchr(rel, '/') : NULL; /* an OGC relation URI: its last word */
        pk_html_link(h, href, slash ? slash + 1 : rel ? rel : href);
        pk_html_raw(h, " ");
    }
    pk_html_raw(h, "</td>");
}

void pk_html_processes(pk_html *h, json_t *doc)
{
    pk_html_raw(h,
                "<table><thead><tr><th>process</th><th>title</th><th>description</th>"
                "<th>version</th><th>links</th></tr></thead><tbody>\n");
    size_t i;
    json_t *p;
    json_array_foreach (json_object_get(doc, "processes"), i, p) {
        static const char *const shown[] = {"title", "description", "version", NULL};
        pk_html_raw(h, "<tr>");
        code_cell(h, p, "id");
        cells(h, p, shown);
        links_cell(h, p);
        pk_html_raw(h, "</tr>\n");
    }
    pk_html_raw(h, "</tbody></table>\n");
}

void pk_html_jobs(pk_html *h, json_t *doc)
{
    pk_html_raw(h, "<p>");
    pk_html_value(h, json_object_get(doc, "numberMatched"));
    pk_html_raw(h, " jobs match; ");
    pk_html_value(h, json_object_get(doc, "numberReturned"));
    pk_html_raw(h, " shown. ");
    size_t i;
    json_t *l;
    json_array_foreach (json_object_get(doc, "links"), i, l) {
        const char *rel = str(l, "rel");
        if (rel && (!strcmp(rel, "prev") || !strcmp(rel, "next"))) {
            pk_html_link(h, str(l, "href"), rel);
            pk_html_raw(h, " ");
        }
    }
    pk_html_raw(h,
                "</p>\n<table><thead><tr><th>job</th><th>process</th><th>status</th>"
                "<th>progress</th><th>message</th><th>created</th><th>finished</th>"
                "<th>links</th></tr></thead><tbody>\n");
    json_t *j;
    json_array_foreach (json_object_get(doc, "jobs"), i, j) {
        const char *status = str(j, "status");
        static const char *const process[] = {"processID", NULL};
        static const char *const shown[] = {"progress", "message", "created", "finished", NULL};
        pk_html_raw(h, "<tr>");
        code_cell(h, j, "jobID");
        cells(h, j, process);
        pk_html_raw(h, "<td class=\"status st-");
        pk_html_text(h, status);
        pk_html_raw(h, "\">");
        pk_html_text(h, status);
        pk_html_raw(h, "</td>");
        cells(h, j, shown);
        links_cell(h, j);
        pk_html_raw(h, "</tr>\n");
    }
    pk_html_raw(h, "</tbody></table>\n");
}
