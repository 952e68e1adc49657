#!/bin/sh
# test_data_privacy.sh — the data directory stays private.  Its files are
# 0640 at most whoever creates them first and whatever the umask (`packd
# token add` before the first `serve`, `packd backup`, a looser queue.db of
# an older version is tightened); and no message or document a client sees
# names a path inside it: a job failing on an uploaded file, its status,
# events, problem document, the job list and the dashboard's copy of its
# inputs (which shows the upload as the link it was given as).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# --- modes under umask 000 --------------------------------------------------
D="$T/modes"
(umask 000 && "$PACKD" token add alice --data "$D" >/dev/null 2>&1)
check token_add_db_0640 test "$(stat -c %a "$D/queue.db")" = 640
(umask 000 && "$PACKD" backup "$T/copy.db" --data "$D" >/dev/null)
check backup_copy_0640 test "$(stat -c %a "$T/copy.db")" = 640
chmod 0666 "$D/queue.db"
(umask 000 && "$PACKD" token add bob --data "$D" >/dev/null 2>&1)
check loose_db_tightened test "$(stat -c %a "$D/queue.db")" = 640
# the daemon's own files, its queue's -wal and -shm included
(umask 000 && exec "$PACKD" serve --port 0 --data "$D" --workers 1 --auth off 2>"$T/modes.log") &
DPID=$!
DAEMONS="$DAEMONS $DPID"
wait_for 20 grep -q '"msg":"listening"' "$T/modes.log"
B="http://127.0.0.1:$(grep -o '"port":[0-9]*' "$T/modes.log" | cut -d: -f2)"
J=$(submit "$T/fast.json")
wait_status "$J" successful 60
c -o /dev/null -H 'Content-Type: application/octet-stream' --data-binary "@$T/fast.json" "$B/files"
loose=$(find "$D" \( -type f -perm /0137 \) -o \( -type d -perm /0027 \) | head -5)
check serve_umask000_files_0640 sh -c "[ -f '$D/queue.db-wal' ] && [ -f '$D/jobs/$J/result.h5' ] && [ -z '$loose' ]"
[ -n "$loose" ] && ls -ld $loose

# --- no data path in what a client sees -------------------------------------
start_daemon paths --workers 1 || { fail serve_starts; exit 1; }
DATA="$T/paths"
printf 'no mesh here\n' >"$T/junk"
c -o "$T/up.json" -H 'Content-Type: application/octet-stream' --data-binary "@$T/junk" "$B/files"
HREF=$(member "$T/up.json" href)
body_of "$SRC/examples/tetfill-cylinder.json" "i['domain']['mesh'] = {'href': '$HREF'}" >"$T/junk.json"
J=$(submit "$T/junk.json")
check junk_job_fails wait_status "$J" failed 60
c -o "$T/v.status" "$B/jobs/$J"
c -o "$T/v.results" "$B/jobs/$J/results"
c -o "$T/v.list" "$B/jobs"
c -o "$T/v.inputs" "$B/dashboard/jobs/$J/inputs"
c -o "$T/v.events" --max-time 5 -H 'Accept: text/event-stream' "$B/jobs/$J/events"
echo "failure message: $(jget "$T/v.status" 'd["message"]')"
check failure_keeps_reason grep -q 'neither a Gmsh MSH file' "$T/v.status"
check failure_names_upload_link grep -q "$HREF" "$T/v.status"
for v in status results list inputs events; do
    check "no_data_path_in_$v" sh -c "[ -s '$T/v.$v' ] && ! grep -q '$DATA' '$T/v.$v'"
done
check inputs_show_the_link test "$(jget "$T/v.inputs" 'd["inputs"]["domain"]["mesh"]["href"]')" = "$B$HREF"
# the worker itself read the file under the data directory (the job ran as submitted)
check worker_read_data_path grep -q "$DATA/files/" "$DATA/jobs/$J/job.json"
exit 0
