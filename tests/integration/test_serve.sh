#!/bin/sh
# test_serve.sh — packd serve end to end over HTTP (real daemon, random
# loopback port, real SQLite file): discovery documents, submit -> poll ->
# download -> h5dump with the SHA-256 header checked by sha256sum, byte
# ranges and ETags, SSE history and resume, idempotency keys, 20 concurrent
# submissions, uploads, metrics, and every error path as problem+json.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

start_daemon d1 --workers 2 --max-body-bytes 65536 || { fail serve_starts; exit 1; }
pass serve_starts

# 1. discovery
c "$B/" >"$T/land.json"
check landing_links_absolute sh -c "grep -q '\"$B/processes\"' '$T/land.json' && grep -q '\"service-desc\"' '$T/land.json'"
c "$B/conformance" >"$T/conf.json"
check conformance grep -q 'ogcapi-processes-1/1.0/conf/core' "$T/conf.json"
c -D "$T/api.h" "$B/api" >"$T/api.json"
check openapi_served_as_is sh -c "cmp -s '$T/api.json' '$SRC/schemas/openapi.json' && grep -qi 'content-type: application/vnd.oai.openapi+json' '$T/api.h'"
c "$B/processes" >"$T/procs.json"
check processes_list_pack test "$(jget "$T/procs.json" '[p["id"] for p in d["processes"]].count("pack")')" = 1
c "$B/processes/pack" >"$T/pack.json"
check process_description_schema test "$(jget "$T/pack.json" 'd["inputs"]["dim"]["schema"]["enum"] == [2, 3] and d["inputsSchema"]["$id"] == "pack.inputs.schema.json"')" = True

# 2. submit -> poll -> results -> download -> open the HDF5
ID=$(submit "$T/fast.json")
check submit_201_location sh -c "grep -q '^HTTP/1.1 201' '$T/submit.h' && grep -qi '^location: $B/jobs/$ID' '$T/submit.h'"
check job_successful wait_status "$ID" successful 60
c "$B/jobs/$ID/results" >"$T/res.json"
check results_document test "$(jget "$T/res.json" 'd["summary"]["value"]["count_placed"] == 1000 and d["result"]["href"] == "'"$B"'/jobs/'"$ID"'/results/result"')" = True
c -D "$T/dl.h" -o "$T/r.h5" "$B/jobs/$ID/results/result"
hdr_sha=$(grep -i '^x-content-sha256:' "$T/dl.h" | tr -d '\r' | awk '{print $2}')
file_sha=$(sha256sum "$T/r.h5" | awk '{print $1}')
check download_sha256_header sh -c "[ -n '$hdr_sha' ] && [ '$hdr_sha' = '$file_sha' ] && [ '$hdr_sha' = '$(jget "$T/res.json" 'd["result"]["sha256"]')' ]"
len=$(grep -i '^content-length:' "$T/dl.h" | tr -d '\r' | awk '{print $2}')
check download_content_length test "$len" = "$(wc -c <"$T/r.h5")"
check download_opens_in_h5dump sh -c "h5dump -d /particles/grains/radius '$T/r.h5' | grep -q 'DATASPACE  SIMPLE { ( 1000 )'"
c -D "$T/rg.h" -r 100-199 -o "$T/part" "$B/jobs/$ID/results/result"
check range_206 sh -c "grep -q '^HTTP/1.1 206' '$T/rg.h' && grep -qi 'content-range: bytes 100-199/$len' '$T/rg.h' && tail -c +101 '$T/r.h5' | head -c 100 | cmp -s - '$T/part'"
c -D "$T/rg2.h" -o /dev/null -r "$((len + 10))-" "$B/jobs/$ID/results/result"
check range_416 grep -q '^HTTP/1.1 416' "$T/rg2.h"
# XDMF for ParaView: names the downloaded HDF5 file and its datasets
c -D "$T/x.h" -o "$T/$ID.xdmf" "$B/jobs/$ID/results/xdmf"
cp "$T/r.h5" "$T/$ID.h5"
check download_xdmf python3 "$SRC/tests/tools/xdmf_check.py" "$T/$ID.xdmf" --points 1000
check download_xdmf_names_download grep -q ">$ID.h5:/particles/grains/position<" "$T/$ID.xdmf"
# pictures drawn by the worker beside the result, listed in the results document, shown inline
check pictures_listed_in_results test "$(jget "$T/res.json" 'd["picture.png"]["href"] == "'"$B"'/jobs/'"$ID"'/results/picture.png" and d["grading.svg"]["type"] == "image/svg+xml"')" = True
c -D "$T/pic.h" -o "$T/pic.png" "$B/jobs/$ID/results/picture.png"
check picture_png_served sh -c "grep -qi '^content-type: image/png' '$T/pic.h' && ! grep -qi '^content-disposition' '$T/pic.h' && head -c 8 '$T/pic.png' | od -An -c | grep -q 'P   N   G'"
c -o "$T/nopic.json" "$B/jobs/$ID/results/picture.gif"
check picture_unknown_output_404 grep -q 'no-such-output' "$T/nopic.json"
check xdmf_listed_in_results test "$(jget "$T/res.json" 'd["xdmf"]["href"] == "'"$B"'/jobs/'"$ID"'/results/xdmf"')" = True
etag=$(grep -i '^etag:' "$T/dl.h" | tr -d '\r' | cut -d' ' -f2)
check download_etag_304 test "$(c -o /dev/null -w '%{http_code}' -H "If-None-Match: $etag" "$B/jobs/$ID/results/result")" = 304
c -D "$T/job.h" -o /dev/null "$B/jobs/$ID"
jetag=$(grep -i '^etag:' "$T/job.h" | tr -d '\r' | cut -d' ' -f2)
check status_etag_304 test "$(c -o /dev/null -w '%{http_code}' -H "If-None-Match: $jetag" "$B/jobs/$ID")" = 304

# 3. SSE: the whole history, then the stream ends by itself after the final status
c -N "$B/jobs/$ID/events" >"$T/sse.txt"
rc=$?
check sse_progress_and_final sh -c "[ $rc -eq 0 ] && grep -q '^event: progress' '$T/sse.txt' && grep -q '\"phi\"' '$T/sse.txt' && tail -3 '$T/sse.txt' | grep -q '\"status\":\"successful\"'"
first=$(grep -m1 '^id: ' "$T/sse.txt" | cut -d' ' -f2)
c -N -H "Last-Event-ID: $first" "$B/jobs/$ID/events" >"$T/sse2.txt"
check sse_resume_last_event_id sh -c "! grep -q '^id: $first\$' '$T/sse2.txt' && [ \$(grep -c '^id: ' '$T/sse2.txt') -eq \$((\$(grep -c '^id: ' '$T/sse.txt') - 1)) ]"

# 4. idempotency: same key + same body -> the same job; same key + other body -> 422
I1=$(submit "$T/fast.json" -H 'Idempotency-Key: run-42')
I2=$(submit "$T/fast.json" -H 'Idempotency-Key: run-42')
check idempotent_same_job sh -c "[ -n '$I1' ] && [ '$I1' = '$I2' ] && grep -qi 'idempotent-replayed: true' '$T/submit.h'"
body_of "$SRC/examples/meier-quartz-2d.json" "i['seed'] = 99" >"$T/other.json"
code=$(c -o "$T/conflict.json" -w '%{http_code}' -H 'Idempotency-Key: run-42' -H 'Content-Type: application/json' --data-binary "@$T/other.json" "$B/processes/pack/execution")
check idempotent_key_reuse_422 sh -c "[ $code = 422 ] && grep -q 'idempotency-key-reused' '$T/conflict.json'"

# 5. 20 concurrent submissions land exactly once each (distinct keys), and 20
#    concurrent retries of one key make one job
before=$(c "$B/jobs?limit=1" | python3 -c 'import json,sys; print(json.load(sys.stdin)["numberMatched"])')
# (wait on the curl pids only: a bare `wait` would wait for the daemon too)
pids=""
for k in $(seq 1 20); do
    c -o "$T/cc.$k" -H "Idempotency-Key: burst-$k" -H 'Content-Type: application/json' --data-binary "@$T/fast.json" "$B/processes/pack/execution" &
    pids="$pids $!"
done
for k in $(seq 1 20); do
    c -o "$T/cs.$k" -H "Idempotency-Key: storm" -H 'Content-Type: application/json' --data-binary "@$T/fast.json" "$B/processes/pack/execution" &
    pids="$pids $!"
done
for p in $pids; do wait "$p"; done
after=$(c "$B/jobs?limit=1" | python3 -c 'import json,sys; print(json.load(sys.stdin)["numberMatched"])')
ids=$(for k in $(seq 1 20); do jget "$T/cc.$k" 'd["jobID"]'; done | sort -u | wc -l)
storm=$(for k in $(seq 1 20); do jget "$T/cs.$k" 'd["jobID"]'; done | sort -u | wc -l)
check concurrent_20_exactly_once sh -c "[ $ids -eq 20 ] && [ $storm -eq 1 ] && [ $((after - before)) -eq 21 ]"
ok=1
for k in $(seq 1 20); do
    wait_status "$(jget "$T/cc.$k" 'd["jobID"]')" successful 60 || ok=0
done
check concurrent_20_all_successful test $ok = 1
c "$B/jobs?status=successful&limit=5" >"$T/list.json"
check job_list_filter_paging test "$(jget "$T/list.json" 'len(d["jobs"]) == 5 and all(j["status"] == "successful" for j in d["jobs"]) and any(l["rel"] == "next" for l in d["links"])')" = True

# 6. uploads
head -c 3000 /dev/urandom >"$T/mesh.bin"
c -o "$T/up.json" -H 'Content-Type: application/octet-stream' --data-binary "@$T/mesh.bin" "$B/files"
href=$(jget "$T/up.json" 'd["href"]')
c -o "$T/down.bin" "$B$href"
check upload_roundtrip sh -c "cmp -s '$T/mesh.bin' '$T/down.bin' && [ '$(jget "$T/up.json" 'd["sha256"]')' = '$(sha256sum "$T/mesh.bin" | cut -d' ' -f1)' ]"

# 7. metrics and health
c "$B/metrics" >"$T/metrics.txt"
check metrics_prometheus sh -c "grep -q '^packd_jobs{status=\"successful\"} [1-9]' '$T/metrics.txt' && grep -q '^packd_queue_depth ' '$T/metrics.txt' && grep -q '^packd_workers_max 2' '$T/metrics.txt' && grep -q '^packd_job_duration_seconds_count{process=\"pack\"}' '$T/metrics.txt'"
check healthz_ready test "$(c -o "$T/h.json" -w '%{http_code}' "$B/healthz")$(jget "$T/h.json" 'd["ready"]')" = 200True

# 8. every error path: status code + application/problem+json + body status
problem() { # name, expected code, curl args...
    name=$1
    want=$2
    shift 2
    got=$(c -D "$T/p.h" -o "$T/p.json" -w '%{http_code}' "$@")
    if [ "$got" = "$want" ] && grep -qi '^content-type: application/problem+json' "$T/p.h" &&
        [ "$(jget "$T/p.json" 'd["status"]')" = "$want" ]; then
        pass "$name"
    else
        fail "$name" "got $got: $(cat "$T/p.json")"
    fi
}
problem error_404_route 404 "$B/no/such/route"
problem error_405_method 405 -X DELETE "$B/processes"
check error_405_allow grep -qi '^allow: GET' "$T/p.h"
head -c 100000 /dev/zero | tr '\0' ' ' >"$T/big.json"
problem error_413_body 413 -H 'Content-Type: application/json' --data-binary "@$T/big.json" "$B/processes/pack/execution"
problem error_400_not_json 400 -H 'Content-Type: application/json' -d '{"inputs": ' "$B/processes/pack/execution"
problem error_400_no_inputs 400 -H 'Content-Type: application/json' -d '{"input": {}}' "$B/processes/pack/execution"
check error_400_pointer test "$(jget "$T/p.json" 'd["errors"][0]["pointer"]')" = /inputs
body_of "$SRC/examples/meier-quartz-2d.json" "i['phi']['value'] = 1.2; i['delta_d'] = -1" >"$T/bad.json"
problem error_422_invalid_inputs 422 -H 'Content-Type: application/json' --data-binary "@$T/bad.json" "$B/processes/pack/execution"
check error_422_pointers_and_rules test "$(jget "$T/p.json" 'sorted((e["pointer"], e["rule"]) for e in d["errors"])')" = "[('/inputs/delta_d', 'minimum'), ('/inputs/phi/value', 'exclusiveMaximum')]"
problem error_no_such_process 404 -H 'Content-Type: application/json' -d '{"inputs": {}}' "$B/processes/fe9/execution"
check error_no_such_process_type grep -q 'no-such-process' "$T/p.json"
problem error_no_such_job 404 "$B/jobs/00000000-0000-4000-8000-000000000000"
check error_no_such_job_type grep -q 'ogcapi-processes-1/1.0/no-such-job' "$T/p.json"
problem error_no_such_job_delete 404 -X DELETE "$B/jobs/nope"
problem error_no_such_job_results 404 "$B/jobs/nope/results"
problem error_no_such_output 404 "$B/jobs/$ID/results/mesh"
code=$(c -o "$T/jf.json" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$SRC/examples/fuller-3d-periodic.json" "$B/processes/pack/execution")
check job_file_is_a_valid_body test "$code $(jget "$T/jf.json" 'd["status"] in ("accepted", "running")')" = "201 True"
problem error_400_process_mismatch 400 -H 'Content-Type: application/json' -d '{"process": "homogenize", "inputs": {}}' "$B/processes/pack/execution"
problem error_bad_job_query 400 "$B/jobs?status=sleeping"
