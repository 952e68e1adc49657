#!/bin/sh
# test_serve_callbacks.sh — OGC "subscriber" callbacks (daemon/http/callbacks.h)
# against a real HTTP receiver on loopback (callback_receiver.py): a job's
# accepted/running statusInfo reaches inProgressUri, its results document
# successUri; a failed job's statusInfo failedUri; a 500 is retried; a
# receiver that hangs holds up no other owner's callbacks; a
# loopback receiver is refused unless callback_allow lists it; a subscriber
# that is not http(s) is a 400 naming the field; /conformance says callback.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

python3 "$SRC/tests/integration/callback_receiver.py" "$T/port" "$T/posts.jsonl" &
RECEIVER=$!
DAEMONS="$DAEMONS $RECEIVER"
wait_for 10 test -s "$T/port" || { fail receiver_starts; exit 1; }
R="http://127.0.0.1:$(cat "$T/port")"

printf 'workers = 2\ncallback_allow = 127.0.0.1\n' >"$T/cb.conf"
start_daemon cb --config "$T/cb.conf" || { fail serve_starts; exit 1; }

# with_subscriber BODY OUT SUCCESS PROGRESS FAILED: BODY with a subscriber
with_subscriber() {
    python3 -c "
import json, sys
b = json.load(open(sys.argv[1]))
b['subscriber'] = {k: v for k, v in zip(('successUri', 'inProgressUri', 'failedUri'), sys.argv[3:]) if v}
json.dump(b, open(sys.argv[2], 'w'))" "$@"
}
# posted PATH JOB [STATUS]: the receiver got a POST on PATH about JOB (with STATUS)
posted() {
    python3 - "$T/posts.jsonl" "$@" <<'PY'
import json, sys
log, path, job = sys.argv[1:4]
status = sys.argv[4] if len(sys.argv) > 4 else None
for line in open(log):
    p = json.loads(line)
    b = json.loads(p["body"])
    if p["path"] == path and b.get("jobID") == job and (status is None or b.get("status") == status):
        sys.exit(0)
sys.exit(1)
PY
}
count() { grep -c "\"path\": \"$1\"" "$T/posts.jsonl"; }
touch "$T/posts.jsonl"

with_subscriber "$T/fast.json" "$T/ok.json" "$R/ok" "$R/progress" "$R/failed"
OK=$(submit "$T/ok.json")
check success_posted wait_for 60 posted /ok "$OK"
check success_is_results_document python3 -c "
import json
for line in open('$T/posts.jsonl'):
    p = json.loads(line)
    if p['path'] == '/ok':
        b = json.loads(p['body'])
        assert b['jobID'] == '$OK' and b['result']['href'].startswith('$B/jobs/$OK/'), b
        assert b['summary']['value']['complete'] is True
"
check in_progress_posted posted /progress "$OK" running
check no_failure_posted test "$(count /failed)" = 0

slow_body 1 >"$T/slow1.json"
with_subscriber "$T/slow1.json" "$T/bad.json" "$R/ok" "" "$R/failed"
BAD=$(submit "$T/bad.json")
check failure_posted wait_for 60 posted /failed "$BAD" failed

with_subscriber "$T/fast.json" "$T/flaky.json" "$R/flaky"
FL=$(submit "$T/flaky.json")
check retried_after_500 wait_for 30 sh -c "[ \$(grep -c '\"path\": \"/flaky\"' '$T/posts.jsonl') -ge 2 ]"
check retry_logged grep -q '"msg":"callback failed: retrying"' "$LOG"

# deliveries run side by side: while alice's receiver hangs (no answer for
# 30 s; the daemon gives up on each attempt after 10 s and retries), bob's
# job's callback arrives as soon as it is done (one after the other, it
# would wait >= 10 s behind the hung one)
for who in alice bob; do
    tok=$("$PACKD" token add "$who" --data "$T/owners" 2>/dev/null) || fail "token_$who"
    printf 'Authorization: Bearer %s\n' "$tok" >"$T/$who.h"
done
printf 'auth = on\nworkers = 2\ncallback_allow = 127.0.0.1\n' >"$T/owners.conf"
start_daemon owners --config "$T/owners.conf" || { fail serve_starts_owners; exit 1; }
with_subscriber "$T/fast.json" "$T/hang.json" "$R/hang/stall" "$R/hang/stall"
HANG=$(submit "$T/hang.json" -H "@$T/alice.h")
check hung_receiver_reached wait_for 30 sh -c "grep -q '\"path\": \"/hang/stall\"' '$T/posts.jsonl'"
with_subscriber "$T/fast.json" "$T/other.json" "$R/other"
OTHER=$(submit "$T/other.json" -H "@$T/bob.h")
check other_owner_not_held_up wait_for 8 posted /other "$OTHER"
check hung_one_retried wait_for 30 sh -c "grep '\"msg\":\"callback failed: retrying\"' '$LOG' | grep -q '$HANG'"

# refused: 127.0.0.1 is loopback, and this daemon does not allow it
start_daemon strict --workers 1 || { fail serve_starts_strict; exit 1; }
with_subscriber "$T/fast.json" "$T/lo.json" "$R/lo"
LO=$(submit "$T/lo.json")
refused() { grep '"msg":"callback given up"' "$LOG" | grep -q "127.0.0.1 is a private, loopback"; }
check loopback_refused wait_for 30 refused
check loopback_not_posted test "$(count /lo)" = 0

# the request names the field and the rule
for sub in '{"successUri": "ftp://127.0.0.1/x"}' '{"successUri": "/relative"}' '{"doneUri": "http://a/"}' '"http://a/"'; do
    python3 -c "
import json, sys
b = json.load(open('$T/fast.json')); b['subscriber'] = json.loads(sys.argv[1])
json.dump(b, open('$T/inv.json', 'w'))" "$sub"
    code=$(c -o "$T/inv.out" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$T/inv.json" "$B/processes/pack/execution")
    check "invalid_subscriber_400_$(echo "$sub" | tr -dc 'a-z' | cut -c1-12)" sh -c "[ '$code' = 400 ] && grep -q '/subscriber' '$T/inv.out'"
done
c -o "$T/conf.json" "$B/conformance"
check conformance_callback grep -q 'ogcapi-processes-1/1.0/conf/callback' "$T/conf.json"
