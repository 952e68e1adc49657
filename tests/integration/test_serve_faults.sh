#!/bin/sh
# test_serve_faults.sh — faults keep their reason: a full data disk fails the
# job with "No space left on device" (no crash, no half file), refuses
# submissions with 503 + Retry-After, makes /healthz not ready, and all of it
# recovers by itself once space returns; job files are 0640 at most (data
# directories 0750); integer query parameters are range-checked (400 naming
# the parameter and its range).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# --- integer query parameters -------------------------------------------
start_daemon q1 || { fail serve_starts; exit 1; }
code=$(c -o "$T/q.json" -w '%{http_code}' "$B/jobs?offset=9223372036854775807")
check query_offset_overflow_400 sh -c "[ '$code' = 400 ] && grep -q 'offset: an integer in 0\.\.' '$T/q.json'"
code=$(c -o "$T/q.json" -w '%{http_code}' "$B/jobs?limit=0")
check query_limit_range_400 sh -c "[ '$code' = 400 ] && grep -q 'limit: an integer, 1 or more' '$T/q.json'"
code=$(c -o "$T/q.json" -w '%{http_code}' "$B/jobs?offset=12x")
check query_offset_not_integer_400 test "$code" = 400
code=$(c -o "$T/q.json" -w '%{http_code}' "$B/jobs?limit=5&offset=0")
check query_in_range_200 test "$code" = 200
kill -0 "$DPID" 2>/dev/null
check query_daemon_alive test $? = 0

# --- file modes: nothing for other accounts, nothing group-writable -------
F=$(submit "$T/fast.json")
wait_status "$F" successful 30
c -o /dev/null -H 'Content-Type: application/octet-stream' --data-binary "@$T/fast.json" "$B/files"
D="$T/q1"
ls -ld "$D" "$D/jobs" "$D/jobs/$F" "$D/jobs/$F/job.json" "$D/jobs/$F/result.h5" "$D/queue.db" >"$T/modes.txt" 2>&1
loose=$(find "$D" \( -type f -perm /0137 \) -o \( -type d -perm /0027 \) | head -5)
check modes_job_files_0640 sh -c "[ -f '$D/jobs/$F/job.json' ] && [ -f '$D/jobs/$F/result.h5' ] && [ -z '$loose' ]"
[ -n "$loose" ] && { echo "too open:"; ls -ld $loose; }
check modes_data_dir_0750 test "$(stat -c %a "$D")" = 750

# --- disk full --------------------------------------------------------------
mkdir -p "$T/full"
if ! mount -t tmpfs -o size=8m tmpfs "$T/full" 2>"$T/mount.err"; then
    skip disk_full "cannot mount a tmpfs here ($(cat "$T/mount.err")); needs root"
    exit 0
fi
trap 'cleanup; umount "$T/full" 2>/dev/null; rm -rf "$T"' EXIT
cleanup_full() { umount "$T/full" 2>/dev/null; }
mkdir "$T/full/data"
ln -s "$T/full/data" "$T/fulldata"
start_daemon fulldata || { fail serve_starts_on_tmpfs; exit 1; }
# a result of ~1.9 MB (50 000 spheres) with ~1 MB left: the queue's writes fit, the file does not
body_of "$SRC/examples/meier-quartz-2d.json" "
i.clear()
i.update({'dim': 3, 'domain': {'box': {'size': [51, 51, 51], 'periodic': True}},
          'grading': {'type': 'classes', 'classes': [{'d': 1.0, 'volume_percent': 100}]},
          'sampling': 'discrete', 'count': 50000, 'phi': {'value': 0.2, 'refers_to': 'resolved'},
          'algorithm': 'rsa', 'seed': 1})" >"$T/big.json"
fill() { # FILE KB-to-leave
    avail=$(df -k --output=avail "$T/full" | tail -1)
    dd if=/dev/zero of="$1" bs=1k count=$((avail - $2)) 2>/dev/null
}
fill "$T/full/fill1" 1024
J=$(submit "$T/big.json")
wait_status "$J" failed 60
msg=$(jget "$T/st.json" 'd["message"]')
echo "disk full job: $msg"
check disk_full_job_names_enospc sh -c "echo '$msg' | grep -qi 'no space left on device' && ! echo '$msg' | grep -qi signal"
left=$(ls "$T/full/data/jobs/$J" | grep -c 'result\|tmp')
check disk_full_no_half_file test "$left" = 0
# now nothing at all is left: the queue cannot take a job
dd if=/dev/zero of="$T/full/fill2" bs=4k 2>/dev/null
code=$(c -D "$T/full.h" -o "$T/full.json" -w '%{http_code}' -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json" "$B/processes/pack/execution")
echo "submit on a full disk: $code $(jget "$T/full.json" 'd["detail"]')"
check disk_full_submit_503_retry_after sh -c "[ '$code' = 503 ] && grep -qi '^Retry-After:' '$T/full.h' && grep -q 'cannot be written' '$T/full.json'"
code=$(c -o "$T/hz.json" -w '%{http_code}' "$B/healthz")
check disk_full_healthz_not_ready test "$code $(jget "$T/hz.json" 'd["database"]')" = "503 error"
# space returns: ready again by itself, jobs run
rm -f "$T/full/fill1" "$T/full/fill2"
i=0
while [ "$(c -o "$T/hz.json" -w '%{http_code}' "$B/healthz")" != 200 ] && [ $i -lt $((50 * SLOW)) ]; do
    sleep 0.1
    i=$((i + 1))
done
check disk_freed_healthz_ready test "$(jget "$T/hz.json" 'd["ready"]')" = True
K=$(submit "$T/fast.json")
check disk_freed_submit_runs wait_status "$K" successful 30
J2=$(submit "$T/big.json")
check disk_freed_big_job_succeeds wait_status "$J2" successful 60
kill -9 "$DPID" 2>/dev/null
wait "$DPID" 2>/dev/null
wait_for 5 no_workers
cleanup_full
