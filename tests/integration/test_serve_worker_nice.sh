#!/bin/sh
# test_serve_worker_nice.sh — worker_nice: a local worker runs at the configured
# niceness and the daemon (its HTTP loops) at its own; out of range (0..19) is
# refused at start, naming the key.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

nice_of() { ps -o ni= -p "$1" | tr -d ' '; }

start_daemon wn --workers 1 --worker-nice 7 || { fail serve_starts; exit 1; }
edmd_slow_body 120 >"$T/slow.json"
ID=$(submit "$T/slow.json")
check job_running wait_status "$ID" running 60
W=$(worker_pid "$ID")
check worker_niceness test "$(nice_of "$W")" = 7
check daemon_niceness_kept test "$(nice_of "$DPID")" = "$(nice_of $$)"
c -o /dev/null -X DELETE "$B/jobs/$ID"
check worker_stopped wait_for 30 dead "$W"

"$PACKD" serve --port 0 --data "$T/wn2" --worker-nice 20 >/dev/null 2>"$T/bad.log" &
BAD=$!
wait "$BAD"
rc=$?
check out_of_range_refused sh -c "[ $rc -ne 0 ] && grep -q worker.nice '$T/bad.log'"
