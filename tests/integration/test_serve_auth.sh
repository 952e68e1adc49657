#!/bin/sh
# test_serve_auth.sh — bearer tokens and owners on a real daemon (loopback,
# auth forced on): 401 + WWW-Authenticate without or with a wrong token, 403
# for a user on an admin route; another owner's job and upload are invisible
# (404 exactly like a missing one) and undeletable, an admin sees and
# dismisses them, and lists one owner's jobs (owner=; a user naming another
# owner lists none; GET /dashboard/me says who is an admin); X-Packd-Owner counts only from the trusted proxy (quotas);
# a revoked token is refused at once; the database holds no token in clear.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# Requests act as $WHO: its header file $T/$WHO.h holds "Authorization: Bearer ...".
WHO=""
c() { curl -s --max-time $((20 * SLOW)) ${WHO:+-H @$T/$WHO.h} "$@"; }
as() { # NAME curl-args...: the HTTP status of a request made as NAME
    WHO=$1
    shift
    c -o "$T/as.out" -D "$T/as.h" -w '%{http_code}' "$@"
    WHO=""
}
token() { # DATA NAME [--admin]: make a token, write NAME's header file
    tok=$("$PACKD" token add "$2" --data "$1" ${3:-} 2>/dev/null) || return 1
    printf 'Authorization: Bearer %s\n' "$tok" >"$T/$2.h"
    printf '%s\n' "$tok" >>"$T/tokens.txt"
}

D="$T/auth"
token "$D" alice && token "$D" bob && token "$D" root --admin
check token_add_prints_token grep -Eq '^Authorization: Bearer packd_[A-Za-z0-9_-]{43}$' "$T/alice.h"
printf 'auth = on\nworkers = 1\n' >"$T/auth.conf"
start_daemon auth --config "$T/auth.conf" || { fail serve_starts; exit 1; }
check startup_log_says_auth_on grep -q '"msg":"auth is on"' "$LOG"

# public documents and /healthz need no token
check healthz_public test "$(as nobody "$B/healthz")" = 200
check landing_public test "$(as nobody "$B/")" = 200

# no token: 401 with the Bearer challenge
code=$(as nobody "$B/jobs")
check no_token_401 sh -c "test $code = 401 && grep -qi '^WWW-Authenticate: Bearer realm=\"packd\"' '$T/as.h'"
printf 'Authorization: Bearer packd_%043d\n' 0 >"$T/wrong.h"
code=$(as wrong "$B/jobs")
check wrong_token_401 sh -c "test $code = 401 && grep -qi '^WWW-Authenticate: Bearer.*error=\"invalid_token\"' '$T/as.h'"
printf 'Authorization: Basic YWxpY2U6eA==\n' >"$T/basic.h"
check other_scheme_401 test "$(as basic "$B/jobs")" = 401
# refused from its headers: a client without a token cannot make the daemon read a body
check no_token_refused_before_body python3 -c "
import socket, sys, time
host, port = '$B'.split('//')[1].split(':')
s = socket.create_connection((host, int(port)), timeout=5)
s.sendall(b'POST /files HTTP/1.1\\r\\nHost: 127.0.0.1\\r\\nContent-Type: application/octet-stream\\r\\n'
          b'Content-Length: 10000000\\r\\n\\r\\n' + b'x' * 1000)
head = s.recv(200).decode('latin-1')
assert head.startswith('HTTP/1.1 401'), head
"
# every route, not only POST: the answer comes from the headers while 9 MB of
# the announced body are still unsent (before, a GET, DELETE, unknown or 405
# route buffered up to max_body_bytes first, without a token)
early() { # EXPECTED-STATUS METHOD PATH [CHUNKED]
    python3 - "$B" "$@" <<'PY'
import socket, sys
base, want, method, path = sys.argv[1:5]
chunked = len(sys.argv) > 5
host, port = base.split('//')[1].split(':')
s = socket.create_connection((host, int(port)), timeout=5)
framing = b'Transfer-Encoding: chunked\r\n\r\n3e8\r\n' if chunked else b'Content-Length: 10000000\r\n\r\n'
s.sendall(('%s %s HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/octet-stream\r\n' % (method, path)).encode()
          + framing + b'x' * 1000)
head = s.recv(200).decode('latin-1')
assert head.startswith('HTTP/1.1 ' + want), head
PY
}
check get_body_refused_before_auth_reads_it early 401 GET /jobs
check delete_body_refused_before_body early 401 DELETE /jobs/00000000-0000-4000-8000-000000000000
check unknown_route_body_404_from_headers early 404 POST /nothing/here
check method_405_from_headers early 405 PUT /jobs
check chunked_get_body_refused early 401 GET /jobs/x/results chunked
check submit_without_token_401 test "$(as nobody -H 'Content-Type: application/json' --data-binary "@$T/fast.json" \
    "$B/processes/pack/execution")" = 401
check metrics_user_403 test "$(as alice "$B/metrics")" = 403
check metrics_admin_200 test "$(as root "$B/metrics")" = 200

# alice uploads a file and runs a job
as alice -H 'Content-Type: application/octet-stream' --data-binary "@$SRC/tests/data/meshes/cylinder41.msh" \
    "$B/files" >/dev/null
HREF=$(member "$T/as.out" href)
WHO=alice
ID=$(submit "$T/fast.json")
check alice_job_successful wait_status "$ID" successful 60
WHO=""

# bob sees nothing of it: every answer is the one for a job that does not exist
as bob "$B/jobs" >/dev/null
check bob_list_empty sh -c "! grep -q '$ID' '$T/as.out' && grep -q '\"numberMatched\": 0' '$T/as.out'"
as bob "$B/jobs/00000000-0000-4000-8000-000000000000" >/dev/null
cp "$T/as.out" "$T/missing.out"
check bob_get_404 test "$(as bob "$B/jobs/$ID")" = 404
grep -v '"detail"' "$T/as.out" >"$T/bob404.out"
check bob_404_like_missing sh -c "grep -q '\"detail\": \"$ID\"' '$T/as.out' && grep -v '\"detail\"' '$T/missing.out' | cmp -s - '$T/bob404.out'"
check bob_events_404 test "$(as bob "$B/jobs/$ID/events")" = 404
check bob_results_404 test "$(as bob "$B/jobs/$ID/results")" = 404
check bob_download_404 test "$(as bob "$B/jobs/$ID/results/result")" = 404
check bob_delete_404 test "$(as bob -X DELETE "$B/jobs/$ID")" = 404
check alice_job_survives test "$(as alice "$B/jobs/$ID/results/result")" = 200
check bob_upload_404 test "$(as bob "$B/files/${HREF#/files/}")" = 404
# (bodies made without python: the links are resolved before the inputs are validated)
printf '{"inputs": {"domain": {"mesh": {"href": "%s"}}}}' "$HREF" >"$T/mesh.json"
code=$(as bob -H 'Content-Type: application/json' --data-binary "@$T/mesh.json" "$B/processes/pack/execution")
check bob_link_upload_422 sh -c "test $code = 422 && grep -q 'no uploaded file' '$T/as.out'"
printf '{"inputs": {"rve": {"href": "/jobs/%s/results/result"}}}' "$ID" >"$T/homog.json"
code=$(as bob -H 'Content-Type: application/json' --data-binary "@$T/homog.json" "$B/processes/homogenize/execution")
check bob_link_job_422 sh -c "test $code = 422 && grep -q 'does not exist' '$T/as.out'"
# the same bytes uploaded by bob are bob's too
as bob -H 'Content-Type: application/octet-stream' --data-binary "@$SRC/tests/data/meshes/cylinder41.msh" \
    "$B/files" >/dev/null
check bob_own_upload test "$(as bob "$B/files/${HREF#/files/}")" = 200

# the owner filter (GET /jobs?owner=): an admin's list narrowed to one owner;
# a user naming another owner gets none of that owner's jobs
WHO=bob
BOB_ID=$(submit "$T/fast.json")
WHO=""
listed() { python3 -c "import json,sys; print(' '.join(j['jobID'] for j in json.load(open('$T/as.out'))['jobs']))"; }
as root "$B/jobs?owner=alice&limit=50" >/dev/null
check admin_owner_filter sh -c "test '$(listed)' = '$ID' && grep -q '\"numberMatched\": 1' '$T/as.out'"
check admin_owner_filter_paging_link grep -q 'owner=alice' "$T/as.out"
as root "$B/jobs?owner=bob&limit=50" >/dev/null
check admin_owner_filter_other test "$(listed)" = "$BOB_ID"
as bob "$B/jobs?owner=alice" >/dev/null
check user_owner_filter_isolated sh -c "! grep -q '$ID' '$T/as.out' && grep -q '\"numberMatched\": 0' '$T/as.out'"
as bob "$B/jobs?owner=bob" >/dev/null
check user_owner_filter_self test "$(listed)" = "$BOB_ID"
check owner_filter_empty_400 sh -c "test $(as root "$B/jobs?owner=") = 400 && grep -q 'owner' '$T/as.out'"
as root "$B/dashboard/me" >/dev/null
check dashboard_me_admin python3 -c "import json; assert json.load(open('$T/as.out')) == {'owner': 'root', 'admin': True}"
as bob "$B/dashboard/me" >/dev/null
check dashboard_me_user python3 -c "import json; assert json.load(open('$T/as.out')) == {'owner': 'bob', 'admin': False}"

# the admin sees and dismisses it
as root "$B/jobs" >/dev/null
check admin_lists_it grep -q "$ID" "$T/as.out"
check admin_delete_200 test "$(as root -X DELETE "$B/jobs/$ID")" = 200
as alice "$B/jobs/$ID" >/dev/null
check alice_sees_dismissed test "$(member "$T/as.out" status)" = dismissed

# revocation takes effect at once; last use is recorded, never the token
check bob_before_revoke test "$(as bob "$B/jobs")" = 200
"$PACKD" token revoke bob --data "$D" 2>/dev/null
check revoked_401 test "$(as bob "$B/jobs")" = 401
"$PACKD" token list --data "$D" >"$T/list.txt"
check list_last_used sh -c "grep -q '^alice .*Z *[0-9-]*T' '$T/list.txt' && grep -q '^root  *yes' '$T/list.txt'"
check list_no_token sh -c "! grep -q packd_ '$T/list.txt'"
check db_no_plaintext sh -c "! grep -aqF -f '$T/tokens.txt' '$D'/queue.db*"
HASH=$(head -1 "$T/tokens.txt" | tr -d '\n' | sha256sum | cut -d' ' -f1)
check db_holds_sha256 sh -c "grep -aq '$HASH' '$D'/queue.db*"

# quotas count the token's owner; X-Packd-Owner only from trusted_proxy (SIGHUP adds it)
D2="$T/quota"
token "$D2" alice
printf 'auth = on\nworkers = 0\nmax_queued_per_owner = 1\n' >"$T/quota.conf"
start_daemon quota --config "$T/quota.conf" || { fail quota_starts; exit 1; }
Q=$LOG
check quota_first_201 test "$(as alice -H 'Content-Type: application/json' --data-binary "@$T/fast.json" \
    "$B/processes/pack/execution")" = 201
check quota_header_ignored_429 test "$(as alice -H 'X-Packd-Owner: someone-else' -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution")" = 429
printf 'trusted_proxy = 127.0.0.1\n' >>"$T/quota.conf"
kill -HUP "$DPID"
i=0
while [ $i -lt 50 ] && ! grep -q '"msg":"configuration reloaded"' "$Q"; do sleep 0.1; i=$((i + 1)); done
check proxy_owner_honoured test "$(as alice -H 'X-Packd-Owner: carol' -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution")" = 201
CAROL=$(member "$T/as.out" jobID)
as alice "$B/jobs" >/dev/null
check proxy_owner_scopes sh -c "! grep -q '$CAROL' '$T/as.out'"
check proxy_still_needs_token test "$(as nobody -H 'X-Packd-Owner: carol' "$B/jobs")" = 401

# auth = auto with a trusted proxy on loopback (the reverse-proxy layout of
# docs/service.md without "auth = on") is on: the proxy forwards anyone
printf 'workers = 0\ntrusted_proxy = 127.0.0.1\n' >"$T/proxy.conf"
start_daemon proxy --config "$T/proxy.conf" || { fail proxy_starts; exit 1; }
check auto_with_proxy_log_on wait_for 5 grep -q 'trusted proxy is configured.*"msg":"auth is on"' "$LOG"
check auto_with_proxy_owner_401 test "$(as nobody -H 'X-Packd-Owner: mallory' "$B/jobs")" = 401
check auto_with_proxy_metrics_401 test "$(as nobody -H 'X-Packd-Owner: mallory' "$B/metrics")" = 401

# the loopback default stays open and says so
start_daemon open || { fail open_starts; exit 1; }
check startup_log_says_auth_off grep -q '"msg":"auth is off"' "$LOG"
check open_no_token_200 test "$(as nobody "$B/jobs")" = 200
check open_log_names_this_host wait_for 5 grep -q 'only processes on this host.*"msg":"auth is off"' "$LOG"
# a route that takes no body refuses one (413) from its headers, auth or not
check open_get_body_413 early 413 GET /healthz
check open_get_chunked_body_413 early 413 GET /jobs chunked
exit 0
