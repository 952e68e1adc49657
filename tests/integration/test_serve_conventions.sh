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
