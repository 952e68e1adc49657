/* GET /processes and /processes/{pid}: read from the process table; the list
 * also as HTML (html_page.h). */
#include "html_page.h"
#include "http.h"
#include "api/http/http_process_doc.h"

enum MHD_Result route_processes(pk_req *r)
{
    json_t *list = json_array();
    for (size_t i = 0; pk_processes[i]; i++)
        json_array_append_new(list, pk_process_summary(pk_processes[i]));
    return pk_send_doc(r,
                       json_pack("{s:o,s:[{s:s,s:s,s:s}]}", "processes", list, "links", "href",
                                 "/processes", "rel", "self", "type", "application/json"),
                       "Processes", pk_html_processes);
}

enum MHD_Result route_process(pk_req *r)
{
    const pk_process *p = pk_process_find(r->seg[1]);
    if (!p)
        return pk_reply_problem(r, PK_P_NO_SUCH_PROCESS, r->seg[1]);
    return pk_send_json(r, 200, pk_process_description(p), NULL);
}
