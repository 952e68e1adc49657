#!/bin/sh
# test_serve_dbfull.sh — the queue's failures are never silent: a worker
# that ends while the data disk (and with it the queue database) is full
# keeps its end until the database takes it: meanwhile /healthz is not ready
# (503, database error, the unrecorded end counted), submissions get 503, the
# log says why; once space returns the end is recorded (the job failed, with
# its reason), /healthz is ready and jobs run again.  A real SQLite file on a
# real 8 MiB tmpfs (needs root for the mount: skipped otherwise).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

mkdir -p "$T/full"
if ! mount -t tmpfs -o size=8m tmpfs "$T/full" 2>"$T/mount.err"; then
    skip db_full "cannot mount a tmpfs here ($(cat "$T/mount.err")); needs root"
    exit 0
fi
# the daemons hold files on it: unmounted lazily before the directory goes
trap 'umount -l "$T/full" 2>/dev/null; cleanup' EXIT
mkdir "$T/full/data"
ln -s "$T/full/data" "$T/dbfull"
start_daemon dbfull --workers 1 || { fail serve_starts_on_tmpfs; exit 1; }

slow_body 60 >"$T/slow.json"
J=$(submit "$T/slow.json")
check job_running wait_status "$J" running 30
# the disk fills up to the last block while the job runs
dd if=/dev/zero of="$T/full/fill" bs=4k 2>/dev/null
dd if=/dev/zero of="$T/full/fill2" bs=512 2>/dev/null
W=$(worker_pid "$J")
check worker_found test -n "$W"
kill -9 "$W"

# the end cannot be written: it is kept, said in the log with the database's error
ended_unrecorded() { grep '"msg":"job end not recorded' "$LOG" | grep -q "\"job\":\"$J\""; }
check end_not_recorded_logged wait_for 20 ended_unrecorded
check end_log_says_why sh -c "grep '\"msg\":\"job end not recorded' '$LOG' | grep -q '\"error\":\"database or disk is full'"
code=$(c -o "$T/hz.json" -w '%{http_code}' "$B/healthz")
echo "healthz with the end pending: $code $(cat "$T/hz.json" | tr -d '\n ')"
check healthz_not_ready_503 test "$code" = 503
check healthz_database_error test "$(jget "$T/hz.json" 'd["database"]')" = error
check healthz_counts_unrecorded_end test "$(jget "$T/hz.json" 'd["unrecorded_job_ends"]')" = 1
code=$(c -o "$T/sub.json" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$T/fast.json" \
    "$B/processes/pack/execution")
check submit_503_while_full test "$code" = 503
check refusal_log_says_why sh -c "grep '\"msg\":\"job refused' '$LOG' | grep -q '\"error\":\"database or disk is full'"
# a second later it is still not ready (a write that fits in the WAL's slack does not count)
sleep 1.2
code=$(c -o "$T/hz.json" -w '%{http_code}' "$B/healthz")
check healthz_stays_not_ready test "$code" = 503

# space returns: the end is recorded by itself, with the worker's reason
rm -f "$T/full/fill" "$T/full/fill2"
check end_recorded_after_space wait_status "$J" failed 20
msg=$(jget "$T/st.json" 'd["message"]')
echo "recorded end: $msg"
check end_keeps_reason sh -c "echo '$msg' | grep -q 'signal 9'"
check end_recorded_logged grep -q '"msg":"job end recorded"' "$LOG"
check healthz_ready_again wait_for 10 sh -c "[ \$(curl -s -o /dev/null -w '%{http_code}' '$B/healthz') = 200 ]"
K=$(submit "$T/fast.json")
check jobs_run_again wait_status "$K" successful 60
exit 0
