#!/bin/sh
# test_serve_conn.sh — no client can starve the others of connections: 1000
# slow-loris and 1000 idle connections (spread over 127.0.0.0/8 sources, as
# many clients would be) leave /healthz answering fast; the per-IP limit
# closes what one address opens beyond it; 300 SSE listeners cost no thread
# each, all wake and end when their job ends; SIGTERM ends streams at once;
# idle connections are closed after idle_timeout_s; a non-JSON body on a JSON
# route is 415.  Clients: conn_client.py (loopback only).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
# The interpreter itself, not a version-manager shim: the clients are started often.
PY=$(python3 -c 'import sys; print(sys.executable)')
CL="$PY $SRC/tests/integration/conn_client.py"
LIMIT_MS=$((100 * SLOW))

# As many connections as the open-files limit allows both sides (both start
# from this shell's limit; each raises its soft limit to the hard one).
hard=$(ulimit -Hn)
[ "$hard" = unlimited ] && hard=100000
N=1000
[ $((2 * N + 300)) -gt $((hard - 200)) ] && N=$(((hard - 500) / 2))
echo "# $N slow-loris + $N idle connections (open-files limit $hard)"

# idle_timeout_s 60: the flood's idle connections stay open while it is measured
start_daemon conn --workers 0 --max-connections-per-ip 64 --idle-timeout-s 60 || exit 1
PORT=${B##*:}
threads() { sed -n 's/^Threads:[[:space:]]*//p' "/proc/$DPID/status"; }
# kv FILE KEY: a value of the client's key=value line
kv() { sed -n "s/.*\<$2=\([^ ]*\).*/\1/p" "$1" | head -1; }
# probe_ok FILE: 0 failures and p99 under the limit
probe_ok() {
    [ "$(kv "$1" fail)" = 0 ] && awk -v p="$(kv "$1" p99_ms)" -v l="$LIMIT_MS" 'BEGIN { exit !(p < l) }'
}
# wait_file FILE SECONDS
wait_file() {
    end=$(($(date +%s) + $2 * SLOW))
    while [ ! -s "$1" ] && [ "$(date +%s)" -le "$end" ]; do sleep 0.1; done
    [ -s "$1" ]
}

# 1. slow-loris + idle flood
timeout 120 $CL hold "$PORT" --slow "$N" --idle "$N" --per-src 50 --src-from 2 --ready "$T/hold.ready" \
    --seconds 60 >"$T/hold.out" &
HOLD=$!
wait_file "$T/hold.ready" 40
echo "# flood: $(cat "$T/hold.ready")"
check flood_all_connections_kept test "$(kv "$T/hold.ready" slow) $(kv "$T/hold.ready" idle) $(kv "$T/hold.ready" closed)" = "$N $N 0"
timeout 60 $CL probe "$PORT" --n 100 >"$T/probe1"
echo "# healthz under the flood: $(cat "$T/probe1"), threads $(threads)"
check flood_healthz_p99 probe_ok "$T/probe1"
# one address beyond max_connections_per_ip: the rest are closed at once
timeout 20 $CL open "$PORT" --n 70 --src 127.0.200.1 --wait 0.5 >"$T/perip"
check per_ip_limit test "$(kv "$T/perip" closed)" = 6
kill "$HOLD" 2>/dev/null
wait "$HOLD"
echo "# flood at its end: $(cat "$T/hold.out")"

# 2. 300 SSE listeners of a waiting job (workers 0: it stays accepted)
ID=$(submit "$T/fast.json")
timeout 120 $CL sse "$PORT" "/jobs/$ID/events" --n 300 --per-src 50 --src-from 300 --ready "$T/sse.ready" \
    --seconds 60 >"$T/sse.out" &
SSE=$!
wait_file "$T/sse.ready" 40
check sse_300_started test "$(kv "$T/sse.ready" started)" = 300
th=$(threads)
echo "# daemon threads with 300 listeners: $th"
check sse_threads_bounded test "${th:-999}" -le 16
timeout 60 $CL probe "$PORT" --n 100 >"$T/probe2"
echo "# healthz with 300 listeners: $(cat "$T/probe2")"
check sse_healthz_p99 probe_ok "$T/probe2"
c -o /dev/null -X DELETE "$B/jobs/$ID"
wait "$SSE"
echo "# listeners: $(cat "$T/sse.out")"
check sse_all_woken_and_ended test "$(kv "$T/sse.out" ended) $(kv "$T/sse.out" status_events)" = "300 600"

# 3. SIGTERM ends the streams promptly and the daemon exits
ID=$(submit "$T/fast.json")
timeout 60 $CL sse "$PORT" "/jobs/$ID/events" --n 50 --src-from 400 --ready "$T/term.ready" --seconds 30 \
    >"$T/term.out" &
SSE=$!
wait_file "$T/term.ready" 40
kill -TERM "$DPID"
end=$(($(date +%s) + 5 * SLOW))
while kill -0 "$DPID" 2>/dev/null && [ "$(date +%s)" -le "$end" ]; do sleep 0.1; done
check sigterm_daemon_exits sh -c "! kill -0 $DPID 2>/dev/null"
wait "$SSE"
check sigterm_streams_end test "$(kv "$T/term.out" ended)" = 50

# 4. idle connections are closed after idle_timeout_s; 415 on a JSON route
start_daemon idle --workers 0 --idle-timeout-s 1 || exit 1
PORT=${B##*:}
timeout 20 $CL open "$PORT" --n 5 --src 127.0.0.1 --wait 2.5 >"$T/idle.out"
check idle_timeout_closes test "$(kv "$T/idle.out" closed)" = 5
code=$(c -o "$T/415.json" -w '%{http_code}' -H 'Content-Type: text/plain' --data-binary "@$T/fast.json" \
    "$B/processes/pack/execution")
check execute_text_plain_415 sh -c "test '$code' = 415 && grep -q 'application/json' '$T/415.json'"
code=$(c -o /dev/null -w '%{http_code}' --data-binary "@$T/fast.json" "$B/processes/pack/execution")
check execute_form_415 test "$code" = 415
code=$(c -o /dev/null -w '%{http_code}' -H 'Content-Type: application/json; charset=utf-8' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution")
check execute_json_charset_201 test "$code" = 201
code=$(c -o /dev/null -w '%{http_code}' -H 'Content-Type: text/plain' --data-binary "@$T/fast.json" "$B/files")
check files_take_any_bytes test "$code" = 201

# 5. a head that trickles (one byte a second: never idle) is closed at
# head_timeout_s; a body slower than its size allows at head_timeout_s +
# size / body_min_rate (here 2 + 1000/1000 = 3 s)
start_daemon deadline --workers 0 --idle-timeout-s 60 --head-timeout-s 2 --body-min-rate 1000 || exit 1
PORT=${B##*:}
timeout 20 $CL hold "$PORT" --slow 5 --src-from 700 --ready "$T/dl.ready" --seconds 5 >"$T/dl.out"
echo "# trickled heads after 5 s: $(cat "$T/dl.out")"
check head_deadline_closes_tricklers test "$(kv "$T/dl.out" closed)" = 5
check body_deadline_by_size python3 - "$PORT" <<'PY'
import socket, sys, time
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=10)
s.sendall(b"POST /files HTTP/1.1\r\nHost: x\r\nContent-Type: application/octet-stream\r\n"
          b"Content-Length: 1000\r\n\r\n")
t0 = time.time()
s.setblocking(False)
while time.time() - t0 < 10:   # 10 bytes a second: 1000 bytes would take 100 s
    try:
        s.send(b"x" * 5)
        if s.recv(1, socket.MSG_PEEK) == b"":
            break
    except BlockingIOError:
        pass
    except OSError:
        break
    time.sleep(0.5)
took = time.time() - t0
assert 2.5 < took < 5, took   # deadline 2 + 1000/1000 = 3 s, swept every 0.25 s
PY

# 6. 33 addresses × 128 trickling connections (4 224 > max_connections 4 096,
# every address at max_connections_per_ip), reopened as soon as closed: a
# 34th address is served at once, because near the limit each new connection
# evicts the one waiting longest for its head.
if [ "$hard" -lt 9000 ]; then
    skip flood_33x128 "open-files limit $hard < 9000"
    exit 0
fi
start_daemon table --workers 0 --idle-timeout-s 60 || exit 1
PORT=${B##*:}
timeout 90 $CL hold "$PORT" --slow 4224 --per-src 128 --src-from 1000 --reconnect 1 --ready "$T/tab.ready" \
    --seconds 30 >"$T/tab.out" &
HOLD=$!
wait_file "$T/tab.ready" 60
echo "# 33 x 128 tricklers: $(cat "$T/tab.ready")"
timeout 60 $CL probe "$PORT" --n 200 --src 127.0.250.250 --interval 0.02 >"$T/probe3"
echo "# healthz of a 34th address under it: $(cat "$T/probe3")"
check flood_33x128_healthz_p99 probe_ok "$T/probe3"
kill "$HOLD" 2>/dev/null
wait "$HOLD"
echo "# tricklers at the end: $(cat "$T/tab.out")"
ev=$(c "$B/metrics" | sed -n 's/^packd_http_connections_closed_total{reason="evicted"} //p')
echo "# evicted as the slowest near the limit: $ev"
check flood_33x128_slowest_evicted test "${ev:-0}" -ge 384
