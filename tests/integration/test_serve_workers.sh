#!/bin/sh
# test_serve_workers.sh — packd serve's worker processes: cancellation of a
# running job (live SSE), a worker killed with SIGKILL fails only its job,
# result-not-ready, a full queue answers 503 + Retry-After, kill -9 of the
# daemon with a job running then restart completes the job, SIGTERM re-queues
# what did not finish in the grace period, SIGHUP reloads the config file.
# Every wait is on a condition (a file's line, a process gone, a status),
# bounded generously only as a guard against a hang.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

has_worker() { [ -n "$(worker_pid "$1")" ]; }
logged() { grep "\"msg\":\"$1\"" "$LOG" | grep -q "$2"; } # msg, pattern

slow_body 60 >"$T/slow.json"   # runs until cancelled (60 s safety net)
slow_body 6 >"$T/slow6.json"   # ends by its own wall-time limit after 6 s: failed, partial file kept
edmd_slow_body 60 >"$T/slow-edmd.json" # an EDMD job that runs until cancelled

printf 'workers = 1\nmax_queued = 1\nlog_level = info\n' >"$T/packd.conf"
start_daemon w1 --config "$T/packd.conf" || { fail serve_starts; exit 1; }

# 1. cancel a running EDMD job: the executor cancels its worker, which
#    ends, the job dismissed; SSE shows live progress and the final status,
#    then ends
S=$(submit "$T/slow-edmd.json")
wait_status "$S" running 20
c -N "$B/jobs/$S/events" >"$T/live.txt" &
sse=$!
wait_for 5 has_worker "$S"
W=$(worker_pid "$S")
wait_for 30 grep -q '^event: progress' "$T/live.txt" # it has reported progress
t0=$(date +%s%N)
code=$(c -o "$T/del.json" -w '%{http_code}' -X DELETE "$B/jobs/$S")
# the worker gets SIGTERM at the executor's next poll and stops at its next
# cancel check (SIGKILL 2 s after SIGTERM if still saving)
[ -n "$W" ] && wait_for 30 gone "$W"
echo "cancel: worker gone $(( ($(date +%s%N) - t0) / 1000000 )) ms after DELETE"
check cancel_dismissed test "$code $(jget "$T/del.json" 'd["status"]')" = "200 dismissed"
check cancel_worker_stopped sh -c "[ -n '$W' ] && ! kill -0 '$W' 2>/dev/null"
wait_for 10 logged "worker ended" "$S"
cancelled_by_executor() { logged "cancelling worker" "$S" && logged "worker ended" "$S.*\"status\":\"dismissed\""; }
check cancel_by_executor cancelled_by_executor
wait_for 10 gone $sse
check sse_live_progress_then_dismissed sh -c "! kill -0 $sse 2>/dev/null && grep -q '^event: progress' '$T/live.txt' && grep -q '\"status\":\"running\"' '$T/live.txt' && tail -3 '$T/live.txt' | grep -q '\"status\":\"dismissed\"'"
problem() { # name, code, curl args... (status + problem+json)
    name=$1
    want=$2
    shift 2
    got=$(c -D "$T/p.h" -o "$T/p.json" -w '%{http_code}' "$@")
    if [ "$got" = "$want" ] && grep -qi '^content-type: application/problem+json' "$T/p.h"; then pass "$name"; else fail "$name" "got $got"; fi
}
problem result_of_dismissed_not_ready 404 "$B/jobs/$S/results"

# 2. a worker killed with SIGKILL fails its job; the daemon serves on
K=$(submit "$T/slow.json")
wait_status "$K" running 20
problem error_result_not_ready 404 "$B/jobs/$K/results/result"
check error_result_not_ready_type grep -q 'result-not-ready' "$T/p.json"
# 3. ...meanwhile the queue (max_queued = 1) takes one more, then says 503
Q=$(submit "$T/fast.json")
problem error_503_queue_full 503 -H 'Content-Type: application/json' --data-binary "@$T/fast.json" "$B/processes/pack/execution"
check error_503_retry_after grep -qi '^retry-after: [0-9]' "$T/p.h"
wait_for 5 has_worker "$K"
kill -9 "$(worker_pid "$K")"
wait_status "$K" failed 20
check worker_sigkill_fails_job sh -c "grep -q 'signal 9' '$T/st.json'"
check daemon_serves_after_worker_crash test "$(kill -0 "$DPID" && c -o /dev/null -w '%{http_code}' "$B/healthz")" = 200
check next_job_runs_after_crash wait_status "$Q" successful 60

# 4. SIGHUP reloads the configuration file (max_queued 1 -> 5)
printf 'workers = 1\nmax_queued = 5\nlog_level = info\n' >"$T/packd.conf"
kill -HUP "$DPID"
wait_for 10 grep -q 'configuration reloaded' "$LOG"
check sighup_reload grep -q 'configuration reloaded' "$LOG"

# 5. kill -9 of the daemon with a job running; restart; the job runs to its
#    wall-time limit (status failed, the reason in its message),
#    and so do the jobs that were waiting (two: the reloaded max_queued = 5
#    takes them where max_queued = 1 refused the second)
R=$(submit "$T/slow6.json")
wait_status "$R" running 20
A1=$(submit "$T/fast.json")
A2=$(submit "$T/fast.json")
check sighup_reload_applied sh -c "[ -n '$A1' ] && [ -n '$A2' ] && [ '$(status_of "$A2")' = accepted ]"
wait_for 5 has_worker "$R"
old_worker=$(worker_pid "$R")
kill -9 "$DPID"
wait_for 10 dead "$old_worker"
check worker_dies_with_daemon dead "$old_worker"
start_daemon w1 --config "$T/packd.conf" || fail restart
check restarted_job_completes wait_status "$R" failed 60
check restart_logged_recovery grep -q '"requeued":1' "$LOG"
ok=0
wait_status "$A1" successful 60 && wait_status "$A2" successful 60 && ok=1
check accepted_jobs_survive_kill9 test $ok = 1

c "$B/jobs/$R" >"$T/rr.json"
check restarted_job_result sh -c "grep -q 'wall time' '$T/rr.json'"
# a failed job's summary stays readable: why it stopped (the dashboard's failed-job page)
code=$(c -o "$T/rs.json" -w '%{http_code}' "$B/jobs/$R/results/summary")
check failed_job_summary_served sh -c "[ $code = 200 ] &&
    python3 -c \"import json; assert 'wall time' in json.load(open('$T/rs.json'))['failure']\""

# 6. SIGTERM: running job gets grace_s (1 s here), then is re-queued; the
#    daemon exits 0; after a restart the job runs to its wall-time limit
kill -9 "$DPID"
start_daemon w2 --workers 1 --grace-s 1 || fail restart2
G=$(submit "$T/slow6.json")
wait_status "$G" running 20
kill -TERM "$DPID"
wait_for 30 gone "$DPID"
wait "$DPID"
check sigterm_clean_exit sh -c "[ $? -eq 0 ] && grep -q 'job re-queued at shutdown' '$LOG' && grep -q '\"msg\":\"stopped\"' '$LOG'"
start_daemon w2 --workers 1 || fail restart3
check sigterm_requeued_job_completes wait_status "$G" failed 60
check logs_are_json_lines python3 -c "
import json,sys
for f in sys.argv[1:]:
    for line in open(f):
        o = json.loads(line); assert {'ts','level','msg'} <= o.keys(), line
" "$T"/*.log
