#!/bin/sh
# test_dashboard.sh — the browser dashboard: GET / negotiates (a browser gets
# the page, a JSON client the landing document as before), its assets carry
# the Content-Security-Policy, and headless Chromium (Debian's chromium,
# driven by playwright-core from npm, cached in the build folder) composes a
# small RSA job in the form made from the input schema, field by field (the
# API's error shown at its field), sees it finish and its summary grouped with
# units; submits an example, watches its bar reach 100 %, sees the picture and downloads the
# result, which h5ls reads; then submits the EDMD example edited to run ~5 s
# and sees its bar strictly between 0 and 100 % while it runs (the values the
# bar showed are printed as a BAR line); then job pages: the status word kept
# through progress events, a failed job's reason, summary and partial file
# (h5ls reads it), a cancel button that dismisses, times in the browser's
# zone; the queue line (GET /dashboard/queue, which answers the counts only,
# to a token when auth is on) as the API counts, the list filtered by status
# and process through the URL hash (kept across a reload) and paged as the API
# pages it; an admin's owner filter; and the list, a job page and the
# filled form no wider than a 390 px viewport
# (dashboard_driver.js).  Screenshots: $PACKD_BUILD/screenshots/.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
BUILD=${PACKD_BUILD:-$(dirname "$PACKD")}

start_daemon dash || exit 1
BROWSER_ACCEPT='text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,*/*;q=0.8'
c -D "$T/h.txt" -o "$T/page.html" -H "Accept: $BROWSER_ACCEPT" "$B/"
check dashboard_page_for_browser grep -qi '^content-type: text/html' "$T/h.txt"
check dashboard_page_csp grep -qi "^content-security-policy: default-src 'self'" "$T/h.txt"
check dashboard_page_no_inline_script sh -c "! grep -qiE '<script>|<script [^>]*>[^<]| on[a-z]+=' '$T/page.html'"
n=0
for accept in '' 'application/json' '*/*' 'application/json, text/html;q=0.5'; do
    n=$((n + 1)) # no Accept, JSON, anything, JSON preferred
    c -D "$T/j.txt" -o "$T/landing.json" ${accept:+-H "Accept: $accept"} "$B/"
    check "dashboard_json_landing_$n" sh -c \
        "grep -qi '^content-type: application/json' '$T/j.txt' &&
         python3 -c \"import json; assert json.load(open('$T/landing.json'))['title'] == 'packd job service'\""
done
c -D "$T/a.txt" -o "$T/app.js" "$B/dashboard/app.js"
check dashboard_script_served grep -qi '^content-type: text/javascript' "$T/a.txt"
c -o "$T/ex.json" "$B/dashboard/examples"
check dashboard_examples_listed python3 -c "
import json; d = json.load(open('$T/ex.json'))['examples']
assert any(e['name'] == 'meier-quartz-2d.json' and e['inputs']['dim'] == 2 for e in d), d"
check dashboard_asset_404 test "$(c -o /dev/null -w '%{http_code}' "$B/dashboard/nope.js")" = 404

# GET /dashboard/queue: counts only (no job ids, no owners); with auth on a token is needed
queue_doc() { # NAME FILE: the document has exactly the counts and the local executor
    check "$1" python3 -c "
import json; d = json.load(open('$2'))
assert set(d) == {'accepted', 'running', 'workers_busy', 'workers_max', 'executor'}, d
assert all(isinstance(d[k], int) and d[k] >= 0 for k in d if k != 'executor'), d
assert d['workers_max'] >= 1 and d['executor'] == 'local', d"
}
c -o "$T/queue.json" "$B/dashboard/queue"
queue_doc dashboard_queue_counts "$T/queue.json"
B_OPEN=$B
tok=$("$PACKD" token add alice --data "$T/auth" 2>/dev/null)
printf 'auth = on\n' >"$T/auth.conf"
start_daemon auth --config "$T/auth.conf" || exit 1
B_AUTH=$B
check dashboard_queue_needs_token test "$(c -o /dev/null -w '%{http_code}' "$B_AUTH/dashboard/queue")" = 401
c -H "Authorization: Bearer $tok" -o "$T/queue_auth.json" "$B_AUTH/dashboard/queue"
queue_doc dashboard_queue_counts_auth "$T/queue_auth.json"
B=$B_OPEN

# --- the browser
CHROMIUM=$(command -v chromium || true)
if [ -z "$CHROMIUM" ]; then
    skip dashboard_browser "Debian's chromium is not installed (apt-get install chromium)"
    exit 0
fi
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    skip dashboard_browser "node/npm are not installed (apt-get install nodejs npm)"
    exit 0
fi
NODE_DIR="$BUILD/node"
PW="$NODE_DIR/node_modules/playwright-core"
if [ ! -f "$PW/package.json" ]; then # installed by make test's dependency step
    why=$(tail -1 "$NODE_DIR/npm.log" 2>/dev/null)
    skip dashboard_browser "playwright-core is not in $NODE_DIR: ${why:-make test installs it (sh tests/tools/playwright.sh $NODE_DIR)}"
    exit 0
fi
SHOTS="$BUILD/screenshots"
mkdir -p "$SHOTS"
rm -f "$SHOTS"/dashboard-*.png "$SHOTS"/result*.h5 "$SHOTS"/partial*.h5
browse() { # TAG [TOKEN]: the driver's PASS/FAIL lines, then the download checked
    PLAYWRIGHT_CORE="$PW" CHROMIUM="$CHROMIUM" SLOW=$SLOW HOME="$T" TOKEN="${2:-}" timeout $((300 * SLOW)) \
        node "$SRC/tests/integration/dashboard_driver.js" "$B" "$SHOTS" meier-quartz-2d.json >"$T/drv.txt" 2>&1
    grep -E '^(PASS|FAIL|SKIP|BAR) ' "$T/drv.txt"
    grep -qE '^(PASS|FAIL) ' "$T/drv.txt" || fail "dashboard_driver$1" "$(tail -3 "$T/drv.txt")"
    check "dashboard_download_is_hdf5$1" sh -c "h5ls '$SHOTS/result$1.h5' | grep -q '^particles'"
    check "dashboard_partial_download_is_hdf5$1" sh -c "h5ls '$SHOTS/partial$1.h5' | grep -q '^particles'"
    id=$(sed -n 's/^JOB //p' "$T/drv.txt")
    c ${2:+-H "Authorization: Bearer $2"} -o "$T/api.h5" "$B/jobs/$id/results/result"
    check "dashboard_download_is_the_result$1" cmp -s "$SHOTS/result$1.h5" "$T/api.h5"
}
browse ""

# auth on: the token typed into the page; pictures and files come as blobs
B=$B_AUTH
browse _auth "$tok"
