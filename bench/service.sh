#!/bin/sh
# bench/service.sh — the job service under load, on loopback (docs/service.md,
# "Connections" and "Bench figures").  One line per case:
#   bench=service case=NAME key=value ...
# Cases:
#   poll_status   100 connections polling a job's status for 20 s (wrk) while two
#                 workers run EDMD jobs: requests/s, p50/p99, errors
#   flood         /healthz while 1000 slow-loris and 1000 idle connections are open
#   sse           1000 SSE listeners of a running EDMD job for 30 s: daemon RSS and
#                 threads, /healthz meanwhile
#   kill9_burst   kill -9 during a burst of 200 submissions, restart: every 201 answered
#                 is present and ends successful; PRAGMA integrity_check
# Needs wrk for poll_status (Debian package `wrk`; that case is skipped without it),
# python3 and sqlite3.  Usage: PACKD=build/packd sh bench/service.sh [CASE...]
# (no CASE: all four).  BENCH_SERVE_ARGS: more `packd serve` options, e.g.
# "--worker-nice 10".
PACKD_SRC=${PACKD_SRC:-$(pwd)}
. "$PACKD_SRC/tests/integration/serve_helpers.inc"
PY=$(python3 -c 'import sys; print(sys.executable)')
CL="$PY $SRC/tests/integration/conn_client.py"
kv() { sed -n "s/.*\<$2=\([^ ]*\).*/\1/p" "$1" | head -1; }
wait_file() { # FILE SECONDS
    end=$(($(date +%s) + $2))
    while [ ! -s "$1" ] && [ "$(date +%s)" -le "$end" ]; do sleep 0.1; done
    [ -s "$1" ]
}
proc() { sed -n "s/^$2:[[:space:]]*\([0-9]*\).*/\1/p" "/proc/$1/status"; }
out() { echo "bench=service $*"; }
CASES=" ${*:-poll_status flood sse kill9_burst} "
want() { case $CASES in *" $1 "*) return 0 ;; esac; return 1; }

# server_le Q BEFORE AFTER: the upper bound (ms) of the bucket of
# packd_http_request_duration_seconds that holds quantile Q of the status polls
# (GET /jobs/{jobId}, 200) answered between two /metrics scrapes: the daemon's
# own share of the latency, without wrk's queueing
server_le() {
    cat "$2" "$3" | awk -v q="$1" -v before="$(wc -l <"$2")" '
        index($0, "packd_http_request_duration_seconds_bucket{method=\"GET\",route=\"/jobs/{jobId}\",code=\"200\"") == 1 {
            match($0, /le="[^"]*"/); le = substr($0, RSTART + 4, RLENGTH - 5)
            if (NR <= before) b[le] = $2; else { a[le] = $2; order[++n] = le }
        }
        END {
            total = a["+Inf"] - b["+Inf"]
            for (i = 1; i <= n; i++)
                if (a[order[i]] - b[order[i]] >= q * total) {
                    print (order[i] == "+Inf" ? "inf" : order[i] * 1000); exit
                }
        }'
}

# wrk's "1.23ms" / "456.00us" / "1.02s" -> milliseconds
wrk_ms() { awk -v v="$1" 'BEGIN { n = v + 0; if (v ~ /us$/) n /= 1000; else if (v ~ /[0-9]s$/) n *= 1000; printf "%.2f", n }'; }

# shellcheck disable=SC2086
start_daemon bench --workers 2 --max-queued-per-owner 1000 ${BENCH_SERVE_ARGS:-} || exit 1
PORT=${B##*:}

# --- poll_status
edmd_slow_body 600 >"$T/edmd.json" # ended by DELETE after the sse case
J1=$(submit "$T/edmd.json")
J2=$(submit "$T/edmd.json")
wait_status "$J1" running 30
wait_status "$J2" running 30
if want poll_status && command -v wrk >/dev/null 2>&1; then
    c "$B/metrics" >"$T/metrics0.txt"
    wrk -t2 -c100 -d20s --latency "$B/jobs/$J1" >"$T/wrk.txt" 2>&1
    c "$B/metrics" >"$T/metrics1.txt"
    rps=$(sed -n 's/^Requests\/sec:[[:space:]]*//p' "$T/wrk.txt")
    p50=$(wrk_ms "$(awk '$1 == "50%" { print $2 }' "$T/wrk.txt")")
    p99=$(wrk_ms "$(awk '$1 == "99%" { print $2 }' "$T/wrk.txt")")
    sock=$(sed -n 's/.*Socket errors: connect \([0-9]*\), read \([0-9]*\), write \([0-9]*\), timeout \([0-9]*\).*/\1 \2 \3 \4/p' "$T/wrk.txt" |
        awk '{ print $1 + $2 + $3 + $4 }')
    non2xx=$(sed -n 's/.*Non-2xx or 3xx responses: \([0-9]*\).*/\1/p' "$T/wrk.txt")
    out "case=poll_status conns=100 seconds=20 workers_busy=$(c "$B/healthz" | sed -n 's/.*"busy": \([0-9]*\).*/\1/p')" \
        "serve_args=$(printf %s "${BENCH_SERVE_ARGS:-none}" | tr " " ,) rps=$rps p50_ms=$p50 p99_ms=$p99 errors=$((${sock:-0} + ${non2xx:-0}))" \
        "server_p50_le_ms=$(server_le 0.5 "$T/metrics0.txt" "$T/metrics1.txt")" \
        "server_p99_le_ms=$(server_le 0.99 "$T/metrics0.txt" "$T/metrics1.txt")" \
        "load=$(cut -d' ' -f1 /proc/loadavg)"
elif want poll_status; then
    echo "# poll_status skipped: wrk is not installed (Debian: apt-get install wrk)"
fi

# --- flood
if want flood; then
    timeout 300 $CL hold "$PORT" --slow 1000 --idle 1000 --per-src 50 --src-from 2 --ready "$T/hold.ready" \
        --seconds 120 >"$T/hold.out" &
    HOLD=$!
    wait_file "$T/hold.ready" 120
    $CL probe "$PORT" --n 200 --interval 0.02 >"$T/probe1"
    out "case=flood slow=$(kv "$T/hold.ready" slow) idle=$(kv "$T/hold.ready" idle)" \
        "refused=$(($(kv "$T/hold.ready" closed) + $(kv "$T/hold.ready" failed)))" \
        "threads=$(proc "$DPID" Threads) healthz_$(sed 's/ / healthz_/g' "$T/probe1")"
    kill "$HOLD"
    wait "$HOLD"
fi

# --- sse: 1000 listeners of a running job for 30 s
if want sse; then
    timeout 300 $CL sse "$PORT" "/jobs/$J1/events" --n 1000 --per-src 50 --src-from 100 --ready "$T/sse.ready" \
        --seconds 200 >"$T/sse.out" &
    SSE=$!
    wait_file "$T/sse.ready" 120
    t0=$(date +%s)
    $CL probe "$PORT" --n 250 --interval 0.1 >"$T/probe2"
    while [ $(($(date +%s) - t0)) -lt 30 ]; do sleep 0.5; done
    out "case=sse listeners=$(kv "$T/sse.ready" started) seconds=30 job=$(status_of "$J1")" \
        "rss_kb=$(proc "$DPID" VmRSS) threads=$(proc "$DPID" Threads) healthz_$(sed 's/ / healthz_/g' "$T/probe2")"
fi
c -o /dev/null -X DELETE "$B/jobs/$J1"
c -o /dev/null -X DELETE "$B/jobs/$J2"
if want sse; then
    wait "$SSE"
    out "case=sse_end $(cat "$T/sse.out")"
fi

# --- kill9_burst
want kill9_burst || exit 0
: >"$T/ids"
$CL burst "$PORT" /processes/pack/execution "$T/fast.json" --n 200 --conc 20 --out "$T/ids" >"$T/burst.out" &
BURST=$!
while [ "$(wc -l <"$T/ids")" -lt 80 ] && kill -0 "$BURST" 2>/dev/null; do sleep 0.02; done
kill -9 "$DPID"
wait "$BURST"
start_daemon bench --workers 2 --max-queued-per-owner 1000 || exit 1
$CL jobs "${B##*:}" "$T/ids" --timeout 300 >"$T/jobs.out"
integrity=$(sqlite3 "$T/bench/queue.db" 'PRAGMA integrity_check;')
out "case=kill9_burst submitted=200 answered_201=$(kv "$T/burst.out" answered)" \
    "present=$(($(kv "$T/jobs.out" total) - $(kv "$T/jobs.out" missing)))" \
    "successful=$(kv "$T/jobs.out" successful) failed=$(kv "$T/jobs.out" failed)" \
    "pending=$(kv "$T/jobs.out" pending) integrity=$integrity"
