#!/bin/sh
# test_serve_links.sh — file inputs by link: upload a Gmsh mesh with POST
# /files, fill it through the service with {"href": "/files/<id>"}; links to
# nothing are refused with their pointer and rule; `packd validate` refuses
# links in job files (they are the service's business).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

start_daemon links --workers 1 || { fail serve_starts; exit 1; }
c -o "$T/up.json" -H 'Content-Type: application/octet-stream' \
    --data-binary "@$SRC/tests/data/meshes/cylinder41.msh" "$B/files"
HREF=$(member "$T/up.json" href)
check upload_href sh -c "printf '%s' '$HREF' | grep -Eq '^/files/[0-9a-f]{64}$'"

body_of "$SRC/examples/tetfill-cylinder.json" "i['domain']['mesh'] = {'href': '$HREF'}" >"$T/mesh.json"
ID=$(submit "$T/mesh.json")
check mesh_by_href_accepted sh -c "grep -q '^HTTP/1.1 201' '$T/submit.h'"
check mesh_by_href_successful wait_status "$ID" successful 120
c -o "$T/res.json" "$B/jobs/$ID/results"
check mesh_by_href_filled test "$(jget "$T/res.json" 'd["summary"]["value"]["count_placed"] > 100')" = True

# a link to an upload that does not exist: 422 naming the pointer and the rule
body_of "$SRC/examples/tetfill-cylinder.json" "i['domain']['mesh'] = {'href': '/files/' + 'ab' * 32}" >"$T/bad.json"
code=$(c -o "$T/bad.out" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$T/bad.json" \
    "$B/processes/pack/execution")
check unknown_upload_422 sh -c "test '$code' = 422 && python3 -c \"
import json; d=json.load(open('$T/bad.out'))
assert any(e['pointer']=='/inputs/domain/mesh/href' and e['rule']=='href' for e in d['errors']), d\""

# a link to a job that has no result
body_of "$SRC/examples/tetfill-cylinder.json" "i['domain']['mesh'] = {'href': '/jobs/00000000-0000-0000-0000-000000000000/results/result'}" >"$T/nojob.json"
code=$(c -o "$T/nojob.out" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$T/nojob.json" \
    "$B/processes/pack/execution")
check unknown_job_link_422 sh -c "test '$code' = 422 && grep -q 'does not exist' '$T/nojob.out'"

# a finished pack job's result as the RVE of a homogenize job (CI pipelines chain jobs this way)
body_of "$SRC/examples/homogenize/rve-rsa-2d.json" >"$T/rve.json"
R=$(submit "$T/rve.json")
wait_status "$R" successful 60
body_of "$SRC/examples/homogenize/homogenize-periodic-2d.json" "
i['rve'] = {'href': '/jobs/$R/results/result'}
i['load']['steps'] = 4
i['output'] = {}" >"$T/homog.json"
c -D "$T/h.h" -o "$T/h.json" -H 'Content-Type: application/json' --data-binary "@$T/homog.json" \
    "$B/processes/homogenize/execution"
H=$(member "$T/h.json" jobID)
check homogenize_by_job_link_accepted grep -q '^HTTP/1.1 201' "$T/h.h"
check homogenize_by_job_link_successful wait_status "$H" successful 180
c -o "$T/hres.json" "$B/jobs/$H/results"
check homogenize_result_document test "$(jget "$T/hres.json" 'd["result"]["href"] == "'"$B"'/jobs/'"$H"'/results/result"')" = True

# packd validate: a job file must name files by path
python3 -c "
import json; j=json.load(open('$SRC/examples/tetfill-cylinder.json')); j['inputs']['domain']['mesh']={'href': '$HREF'}
json.dump(j, open('$T/link-job.json','w'))"
out=$("$PACKD" validate "$T/link-job.json" 2>/dev/null)
rc=$?
check cli_refuses_links sh -c "test $rc -eq 1 && printf '%s' '$out' | grep -q '\"rule\": \"href\"'"
exit 0
