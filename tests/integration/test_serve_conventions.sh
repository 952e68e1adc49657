#!/bin/sh
# test_serve_conventions.sh — the conventions other OGC API – Processes
# servers offer, checked on a real daemon on loopback with curl:
# Preference-Applied on respond-async, process descriptions whose every
# $ref resolves (ref_walk.py), CORS (off by default, preflight answered for
# the configured origins only), HTML for /processes and /jobs (Accept and
# f=html; hostile strings escaped; no inline script) and the service-doc page.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
start_daemon conv --workers 1 || { fail serve_starts; exit 1; }

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
