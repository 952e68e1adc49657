#!/bin/sh
# test_serve_conventions.sh — the conventions other OGC API – Processes
# servers offer, checked on a real daemon on loopback with curl:
# Preference-Applied on respond-async, process descriptions whose every
# $ref resolves (ref_walk.py), CORS (off by default, preflight answered for
# the configured origins only), HTML for /processes and /jobs (Accept and
# f=html; hostile strings escaped; no inline script) and the service-doc page.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
start_daemon conv --workers 1 || { fail serve_starts; exit 1; }
CONV_DATA="$T/conv"

# --- Prefer (RFC 7240) ---------------------------------------------------------
c -D "$T/async.h" -o /dev/null -H 'Content-Type: application/json' -H 'Prefer: respond-async' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution"
check prefer_async_applied grep -qi '^preference-applied: respond-async' "$T/async.h"
check prefer_async_is_201 grep -q '^HTTP/1.1 201' "$T/async.h"
c -D "$T/plain.h" -o /dev/null -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution"
check prefer_none_not_applied sh -c "! grep -qi '^preference-applied' '$T/plain.h'"
# respond-sync with no time to wait: answered async, so respond-sync is not claimed
c -D "$T/sync0.h" -o /dev/null -H 'Content-Type: application/json' -H 'Prefer: respond-sync, wait=0' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution"
check prefer_sync_timeout_not_claimed sh -c "grep -q '^HTTP/1.1 201' '$T/sync0.h' && ! grep -qi '^preference-applied' '$T/sync0.h'"

# --- every $ref of every process description resolves --------------------------
if python3 "$SRC/tests/integration/ref_walk.py" "$B" >"$T/refs.txt" 2>&1; then
    pass process_refs_resolve
else
    fail process_refs_resolve "$(head -5 "$T/refs.txt" | tr '\n' ' ')"
fi

# python-jsonschema (with its referencing library, 4.18+) validates the examples with
# each served inputsSchema alone: a registry that fetches nothing
if python3 -c 'import referencing' 2>/dev/null; then
    check inputs_schema_standalone python3 - "$B" "$SRC" <<'PY'
import glob, json, sys, urllib.request
from jsonschema import Draft202012Validator
from referencing import Registry
from referencing.exceptions import Unresolvable
base, src = sys.argv[1], sys.argv[2]
def retrieve(uri):
    raise Unresolvable(uri)
for p in ("pack", "homogenize", "fe2"):
    schema = json.load(urllib.request.urlopen(base + "/processes/" + p, timeout=20))["inputsSchema"]
    v = Draft202012Validator(schema, registry=Registry(retrieve=retrieve))
    for f in glob.glob(src + "/examples/fe2/*.json") if p == "fe2" else []:
        inputs = json.load(open(f))["inputs"]
        assert not list(v.iter_errors(inputs)), f
        inputs["micro"]["rve"] = {"pack": {"dim": 7}}  # checked by the bundled pack schema
        assert any(list(e.absolute_path) == ["micro", "rve", "pack", "dim"] for e in v.iter_errors(inputs)), f
PY
else
    skip inputs_schema_standalone "python3-jsonschema without the referencing library (4.18+)"
fi

# --- CORS: off by default; preflight answered for configured origins only --------
preflight() { # BASE ORIGIN OUTFILE
    c -o /dev/null -D "$3" -X OPTIONS -H "Origin: $2" -H 'Access-Control-Request-Method: POST' \
        -H 'Access-Control-Request-Headers: authorization, content-type, prefer' \
        "$1/processes/pack/execution"
}
preflight "$B" http://lab.example "$T/pre_off.h"
check cors_off_preflight_answered grep -q '^HTTP/1.1 204' "$T/pre_off.h"
check cors_off_no_allow_origin sh -c "! grep -qi '^access-control-allow' '$T/pre_off.h'"
c -o /dev/null -D "$T/get_off.h" -H 'Origin: http://lab.example' "$B/processes"
check cors_off_get_no_allow_origin sh -c "! grep -qi '^access-control-allow-origin' '$T/get_off.h'"
OFF=$B
start_daemon cors --workers 0 --cors-origins 'http://lab.example, https://tools.example:8443' ||
    { fail serve_starts_cors; exit 1; }
preflight "$B" http://lab.example "$T/pre_ok.h"
check cors_preflight_204 grep -q '^HTTP/1.1 204' "$T/pre_ok.h"
check cors_preflight_origin grep -qi '^access-control-allow-origin: http://lab.example' "$T/pre_ok.h"
check cors_preflight_methods grep -qi '^access-control-allow-methods: .*POST' "$T/pre_ok.h"
check cors_preflight_headers sh -c "grep -i '^access-control-allow-headers:' '$T/pre_ok.h' | grep -qi 'authorization' && grep -i '^access-control-allow-headers:' '$T/pre_ok.h' | grep -qi 'prefer'"
preflight "$B" https://tools.example:8443 "$T/pre_ok2.h"
check cors_preflight_second_origin grep -qi '^access-control-allow-origin: https://tools.example:8443' "$T/pre_ok2.h"
preflight "$B" http://evil.example "$T/pre_other.h"
check cors_other_origin_refused sh -c "! grep -qi '^access-control-allow' '$T/pre_other.h'"
c -o /dev/null -D "$T/get_ok.h" -H 'Origin: http://lab.example' "$B/processes"
check cors_get_allow_origin grep -qi '^access-control-allow-origin: http://lab.example' "$T/get_ok.h"
check cors_get_vary_origin grep -qi '^vary: .*origin' "$T/get_ok.h"
c -o /dev/null -D "$T/post_ok.h" -H 'Origin: http://lab.example' -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution"
check cors_post_exposes_location sh -c "grep -qi '^access-control-allow-origin: http://lab.example' '$T/post_ok.h' && grep -i '^access-control-expose-headers:' '$T/post_ok.h' | grep -qi location"
c -o /dev/null -D "$T/get_other.h" -H 'Origin: http://evil.example' "$B/processes"
check cors_get_other_origin_no_allow sh -c "! grep -qi '^access-control-allow-origin' '$T/get_other.h'"
c -o /dev/null -D "$T/opt_none.h" -X OPTIONS "$B/no/such/path"
check options_unknown_path_404 grep -q '^HTTP/1.1 404' "$T/opt_none.h"
B=$OFF

# --- HTML views of /processes and /jobs; the service-doc ---------------------------
BROWSER_ACCEPT='text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8'
# a job whose stored message is hostile markup (as a failure reason quoting a file could be)
HOSTILE='<script>alert(1)</script><img src=x onerror=alert(2)>"'"'"'&'
id=$(submit "$T/fast.json")
wait_status "$id" successful 60 || fail html_job_finished
python3 -c "
import sqlite3, sys
db = sqlite3.connect(sys.argv[1], timeout=10)
db.execute('UPDATE jobs SET message = ? WHERE id = ?', (sys.argv[2], sys.argv[3]))
db.commit()" "$CONV_DATA/queue.db" "$HOSTILE" "$id"
for list in processes jobs; do
    c -D "$T/$list.h" -o "$T/$list.html" -H "Accept: $BROWSER_ACCEPT" "$B/$list"
    check "html_${list}_by_accept" grep -qi '^content-type: text/html' "$T/$list.h"
    check "html_${list}_csp_no_script" sh -c "grep -i '^content-security-policy:' '$T/$list.h' | grep -q \"default-src 'none'\" && ! grep -i '^content-security-policy:' '$T/$list.h' | grep -qiE 'script-src|unsafe'"
    check "html_${list}_no_script" python3 "$SRC/tests/integration/html_check.py" "$T/$list.html"
    c -D "$T/${list}_f.h" -o "$T/${list}_f.html" -H 'Accept: application/json' "$B/$list?f=html"
    check "html_${list}_by_f" grep -qi '^content-type: text/html' "$T/${list}_f.h"
    c -D "$T/${list}_j.h" -o "$T/$list.json" -H "Accept: $BROWSER_ACCEPT" "$B/$list?f=json"
    check "html_${list}_f_json" sh -c "grep -qi '^content-type: application/json' '$T/${list}_j.h' && python3 -c \"
import json; d = json.load(open('$T/$list.json'))
assert any(l['rel'] == 'alternate' and l['type'] == 'text/html' for l in d['links']), d['links']\""
    check "html_${list}_f_bad_400" test "$(c -o /dev/null -w '%{http_code}' "$B/$list?f=xml")" = 400
done
check html_processes_lists_all sh -c "grep -q '<code>pack</code>' '$T/processes.html' && grep -q '<code>fe2</code>' '$T/processes.html'"
check html_jobs_lists_job grep -q "$id" "$T/jobs.html"
check html_jobs_hostile_escaped grep -qF '&lt;script&gt;alert(1)&lt;/script&gt;&lt;img src=x onerror=alert(2)&gt;&quot;&#39;&amp;' "$T/jobs.html"
# JSON clients are unchanged: no Accept, or JSON preferred
c -D "$T/pj.h" -o "$T/pj.json" "$B/processes"
check html_processes_json_default grep -qi '^content-type: application/json' "$T/pj.h"

c -o "$T/landing.json" "$B/"
check service_doc_link python3 -c "
import json; d = json.load(open('$T/landing.json'))
l = [l for l in d['links'] if l['rel'] == 'service-doc']
assert len(l) == 1 and l[0]['type'] == 'text/html' and l[0]['href'].endswith('/api?f=html'), d['links']"
c -D "$T/apih.h" -o "$T/api.html" "$B/api?f=html"
check service_doc_page sh -c "grep -qi '^content-type: text/html' '$T/apih.h' && grep -q 'swagger-ui-bundle.js' '$T/api.html'"
check service_doc_no_inline_script sh -c "python3 '$SRC/tests/integration/html_check.py' '$T/api.html' && grep -i '^content-security-policy:' '$T/apih.h' | grep -q \"script-src 'self';\""
c -o "$T/bundle.js" -w '%{http_code}' "$B/dashboard/swagger-ui-bundle.js" >"$T/bundle.code"
check service_doc_bundle_served sh -c "test \"\$(cat '$T/bundle.code')\" = 200 && cmp -s '$T/bundle.js' '$SRC/web/swagger-ui-bundle.js'"
check service_doc_license_served sh -c "c() { curl -s --max-time 20 \"\$@\"; }; c '$B/dashboard/swagger-ui-LICENSE.txt' | grep -q 'Apache License'"
c -D "$T/apij.h" -o "$T/api.json" "$B/api"
check api_json_unchanged sh -c "grep -qi '^content-type: application/vnd.oai.openapi+json' '$T/apij.h' && cmp -s '$T/api.json' '$SRC/schemas/openapi.json'"

# --- openapi.json says what the daemon answers ---------------------------------------
check openapi_421_415_html python3 -c "
import json; d = json.load(open('$SRC/schemas/openapi.json'))
ops = [(p, m, o) for p, i in d['paths'].items() for m, o in i.items() if m in ('get', 'post', 'delete', 'options')]
miss = [m + ' ' + p for p, m, o in ops if '421' not in o['responses']]
assert not miss, 'no 421: ' + ', '.join(miss)
for p in ('/processes/{processId}/execution', '/files'):
    assert '415' in d['paths'][p]['post']['responses'], p
for p in ('/processes', '/jobs', '/api'):
    g = d['paths'][p]['get']
    assert 'text/html' in g['responses']['200']['content'], p
    assert any(x.get('\$ref', '').endswith('/f') for x in g.get('parameters', [])), p
assert all('options' in i for i in d['paths'].values())"
REDOCLY="$(cd "${PACKD_BUILD:-$(dirname "$PACKD")}" && pwd)/node/node_modules/.bin/redocly"
if [ -x "$REDOCLY" ]; then
    # no telemetry or update check: the test talks to nothing but loopback
    if HOME="$T" REDOCLY_TELEMETRY=off REDOCLY_SUPPRESS_UPDATE_NOTICE=true \
        timeout $((120 * SLOW)) "$REDOCLY" lint --format=stylish "$SRC/schemas/openapi.json" >"$T/lint.txt" 2>&1; then
        pass openapi_redocly_lint
    else
        fail openapi_redocly_lint "$(grep -m1 ' error ' "$T/lint.txt" || tail -1 "$T/lint.txt")"
    fi
else
    skip openapi_redocly_lint "@redocly/cli is not in build/node (make test installs it: sh tests/tools/playwright.sh build/node)"
fi

# --- the pages in a browser: Swagger UI renders the operations under the CSP --------
BUILD=$(cd "${PACKD_BUILD:-$(dirname "$PACKD")}" && pwd)
PW="$BUILD/node/node_modules/playwright-core"
CHROMIUM=$(command -v chromium || true)
if [ -z "$CHROMIUM" ] || ! command -v node >/dev/null || [ ! -f "$PW/package.json" ]; then
    skip html_browser "needs Debian's chromium, node and playwright-core in $BUILD/node (make test installs them)"
    exit 0
fi
ops=$(python3 -c "
import json; d = json.load(open('$SRC/schemas/openapi.json'))
print(sum(1 for p in d['paths'].values() for m in p if m in ('get', 'post', 'delete', 'put', 'patch')))")
mkdir -p "$BUILD/screenshots"
PLAYWRIGHT_CORE="$PW" CHROMIUM="$CHROMIUM" SLOW=$SLOW HOME="$T" timeout $((120 * SLOW)) \
    node "$SRC/tests/integration/apidoc_driver.js" "$B" "$BUILD/screenshots" "$ops" >"$T/drv.txt" 2>&1
grep -E '^(PASS|FAIL|SKIP) ' "$T/drv.txt"
cat "$T/drv.txt" >&2; grep -qE '^(PASS|FAIL) ' "$T/drv.txt" || fail apidoc_driver "$(grep -m1 -iE 'error|timeout' "$T/drv.txt" || tail -1 "$T/drv.txt")"
