#!/bin/sh
# test_metrics.sh — /metrics tells the truth: packd_jobs_finished_total and
# the packd_job_duration_seconds histogram count a finished job once and
# keep it after the job is dismissed (DELETE) and across a restart; a
# database from before the counters gets them filled from its jobs; the
# exposition passes promtool check metrics where Debian's prometheus package
# is installed, else check_metrics.py (the same rules a scraper applies).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

metric() { # FILE 'name{labels}' -> value
    grep -F "$2 " "$1" | head -1 | cut -d' ' -f2
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
                 "ALTER TABLE jobs DROP COLUMN executor_ref; PRAGMA user_version = 2;")
PY
start_daemon m1 --workers 1 || { fail upgrade_start; exit 1; }
c "$B/metrics" >"$T/m4.txt"
# the dismissed row counts as dismissed, the other as successful
check upgrade_backfills_counters sh -c "[ '$(metric "$T/m4.txt" "$FIN")' = 1 ] && [ '$(metric "$T/m4.txt" 'packd_jobs_finished_total{process="pack",status="dismissed"}')' = 1 ] && [ '$(metric "$T/m4.txt" "$CNT")' = 2 ]"
check upgrade_exposition_well_formed python3 "$SRC/tests/integration/check_metrics.py" "$T/m4.txt"
