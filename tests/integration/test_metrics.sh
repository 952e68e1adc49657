#!/bin/sh
# test_metrics.sh — /metrics tells the truth: packd_jobs_finished_total and
# the packd_job_duration_seconds histogram count a finished job once and
# keep it after the job is dismissed (DELETE) and across a restart; a
# database from before the counters gets them filled from its jobs; the
# process_* metrics describe this daemon (start time, RSS, CPU, open and
# maximum fds); packd_http_request_duration_seconds counts a request under
# its route template and status, never its raw path; the exposition passes
# promtool check metrics (Debian's prometheus package, in install-deps.sh's
# test list) where installed, and check_metrics.py (the same rules a scraper
# applies).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

metric() { # FILE 'name{labels}' -> value
    grep -F "$2 " "$1" | head -1 | cut -d' ' -f2
}
sample() { # FILE name (no labels) -> value
    awk -v n="$2" '$1 == n { print $2; exit }' "$1"
}
stop_daemon() { # the daemon of start_daemon: SIGTERM, wait until gone
    kill -TERM "$DPID"
    i=0
    while kill -0 "$DPID" 2>/dev/null && [ $i -lt $((100 * SLOW)) ]; do sleep 0.1; i=$((i + 1)); done
}
FIN='packd_jobs_finished_total{process="pack",status="successful"}'
CNT='packd_job_duration_seconds_count{process="pack"}'
INF='packd_job_duration_seconds_bucket{process="pack",le="+Inf"}'

start_daemon m1 --workers 1 || { fail serve_starts; exit 1; }
c "$B/metrics" >"$T/m0.txt"
check counters_start_at_zero test "$(metric "$T/m0.txt" "$FIN")" = 0
ID=$(submit "$T/fast.json")
wait_status "$ID" successful 60
c "$B/metrics" >"$T/m1.txt"
check finished_counted_once sh -c "[ '$(metric "$T/m1.txt" "$FIN")' = 1 ] && [ '$(metric "$T/m1.txt" "$CNT")' = 1 ] && [ '$(metric "$T/m1.txt" "$INF")' = 1 ]"
if command -v promtool >/dev/null 2>&1; then
    check promtool_check_metrics sh -c "promtool check metrics <'$T/m1.txt'"
else
    echo "(promtool not installed: the exposition is checked by check_metrics.py only)"
fi
check exposition_well_formed python3 "$SRC/tests/integration/check_metrics.py" "$T/m1.txt"

# process_*: this daemon as the kernel sees it
now=$(date +%s)
check process_start_time sh -c "awk -v s='$(sample "$T/m1.txt" process_start_time_seconds)' -v now=$now \
    'BEGIN { exit !(s > now - 600 * $SLOW && s <= now + 1) }'"
check process_rss test "$(sample "$T/m1.txt" process_resident_memory_bytes)" -gt 1000000
check process_cpu awk -v c="$(sample "$T/m1.txt" process_cpu_seconds_total)" 'BEGIN { exit !(c > 0) }'
check process_fds sh -c "[ '$(sample "$T/m1.txt" process_open_fds)' -ge 3 ] &&
    [ '$(sample "$T/m1.txt" process_open_fds)' -le '$(sample "$T/m1.txt" process_max_fds)' ]"
check process_fds_match_proc test "$(sample "$T/m1.txt" process_max_fds)" = \
    "$(awk '/^Max open files/ { print $4 }' "/proc/$DPID/limits")"

# the request-duration histogram counts a request under its route template
H='packd_http_request_duration_seconds'
JOB404="$H"'_count{method="GET",route="/jobs/{jobId}",code="404"}'
NOROUTE="$H"'_count{method="other",route="unmatched",code="404"}'
n0=$(metric "$T/m1.txt" "$JOB404")
u0=$(metric "$T/m1.txt" "$NOROUTE")
c -o /dev/null "$B/jobs/0badc0de-feed-4bee-8eef-000000000404"
c -o /dev/null "$B/no-such-route-7f3a9/x"
c "$B/metrics" >"$T/h1.txt"
check histogram_counts_request test "$(metric "$T/h1.txt" "$JOB404")" = $((${n0:-0} + 1))
check histogram_inf_bucket_is_count test "$(metric "$T/h1.txt" "$H"'_bucket{method="GET",route="/jobs/{jobId}",code="404",le="+Inf"}')" = \
    "$(metric "$T/h1.txt" "$JOB404")"
check histogram_unmatched_counted test "$(metric "$T/h1.txt" "$NOROUTE")" = $((${u0:-0} + 1))
check histogram_no_raw_paths sh -c "! grep -q -e 0badc0de -e no-such-route '$T/h1.txt'"
check histogram_has_status_poll grep -q "^$H"'_bucket{method="GET",route="/jobs/{jobId}",code="200",le="0.0005"} ' "$T/h1.txt"
if command -v promtool >/dev/null 2>&1; then
    check promtool_check_new_series sh -c "promtool check metrics <'$T/h1.txt'"
fi
check new_series_well_formed python3 "$SRC/tests/integration/check_metrics.py" "$T/h1.txt"

# DELETE a finished job: the job gauge moves, the counters do not
c -X DELETE -o /dev/null "$B/jobs/$ID"
c "$B/metrics" >"$T/m2.txt"
check counter_kept_after_delete sh -c "[ '$(metric "$T/m2.txt" "$FIN")' = 1 ] && [ '$(metric "$T/m2.txt" "$CNT")' = 1 ]"
check gauge_follows_delete test "$(metric "$T/m2.txt" 'packd_jobs{status="dismissed"}')" = 1
check dismissed_finished_not_recounted test "$(metric "$T/m2.txt" 'packd_jobs_finished_total{process="pack",status="dismissed"}')" = 0

# a restart keeps them
stop_daemon
start_daemon m1 --workers 1 || { fail restart; exit 1; }
c "$B/metrics" >"$T/m3.txt"
check counter_kept_across_restart sh -c "[ '$(metric "$T/m3.txt" "$FIN")' = 1 ] && [ '$(metric "$T/m3.txt" "$CNT")' = 1 ]"

# a database from before the counters: the upgrade fills them from its jobs
ID2=$(submit "$T/fast.json")
wait_status "$ID2" successful 60
stop_daemon
python3 - "$T/m1/queue.db" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
# version 2: the schema before the counters (daemon/store/migrations.c, step 2 -> 3)
db.executescript("DROP TABLE job_counts; DROP TABLE job_durations; DROP TABLE duration_buckets;"
                 "ALTER TABLE jobs DROP COLUMN executor_ref; DROP INDEX jobs_by_cache_key;"
                 "ALTER TABLE jobs DROP COLUMN cache_key; PRAGMA user_version = 2;")
PY
start_daemon m1 --workers 1 || { fail upgrade_start; exit 1; }
c "$B/metrics" >"$T/m4.txt"
# the dismissed row counts as dismissed, the other as successful
check upgrade_backfills_counters sh -c "[ '$(metric "$T/m4.txt" "$FIN")' = 1 ] && [ '$(metric "$T/m4.txt" 'packd_jobs_finished_total{process="pack",status="dismissed"}')' = 1 ] && [ '$(metric "$T/m4.txt" "$CNT")' = 2 ]"
check upgrade_exposition_well_formed python3 "$SRC/tests/integration/check_metrics.py" "$T/m4.txt"
