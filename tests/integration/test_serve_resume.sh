#!/bin/sh
# test_serve_resume.sh — a long EDMD job ("until jammed") checkpoints into its
# job directory, reports progress on the way, and after kill -9 of the daemon
# and its worker resumes from its last checkpoint on restart: it finishes with
# fewer events after the resume than an uninterrupted run needs in all, says
# it was resumed (summary and file), and the packing is valid.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# 3000 equal spheres until jammed (jam_body)
N=3000 L=14
jam_body $N $L >"$T/jam.json"
python3 -c "import json,sys; print(json.dumps({'process': 'pack', **json.load(open(sys.argv[1]))}))" \
    "$T/jam.json" >"$T/jam-job.json"

# the uninterrupted run, for its event count (in parallel with the daemon's)
"$PACKD" run "$T/jam-job.json" -o "$T/ref.h5" >"$T/ref.sum" 2>"$T/ref.err" &
ref=$!

printf 'workers = 1\ncheckpoint_interval_s = 0.5\nlog_level = info\n' >"$T/packd.conf"
start_daemon r1 --config "$T/packd.conf" || { fail serve_starts; exit 1; }
J=$(submit "$T/jam.json")
CK="$T/r1/jobs/$J/checkpoint.h5"
# wait for a checkpoint and a good part of the run (progress: the reduced
# pressure on its way to p_max, log scale; 15 % is about a quarter of the events)
end=$(($(date +%s) + 90 * SLOW))
pct=0
while [ "$(date +%s)" -le "$end" ]; do
    c -o "$T/st.json" "$B/jobs/$J"
    pct=$(sed -n 's/^  "progress": \([0-9]*\).*/\1/p' "$T/st.json" | head -1)
    [ -f "$CK" ] && [ "${pct:-0}" -ge 15 ] && break
    [ "$(member "$T/st.json" status)" = successful ] && break
    sleep 0.3
done
echo "before the kill: progress ${pct} %, $(member "$T/st.json" message)"
check resume_progress_moves_before_kill sh -c "[ -f '$CK' ] && [ '${pct:-0}' -ge 15 ] && [ '$(member "$T/st.json" status)' = running ]"
W=$(worker_pid "$J")
kill -9 "$DPID" ${W:+"$W"} 2>/dev/null
wait "$DPID" 2>/dev/null
[ -z "$W" ] || wait_for 10 dead "$W"

start_daemon r1 --config "$T/packd.conf" || { fail serve_restarts; exit 1; }
check resume_job_finishes wait_status "$J" successful $((120))
S="$T/r1/jobs/$J/summary.json"
wait "$ref"
ev_ref=$(jget "$T/ref.sum" 'd["edmd"]["events"]')
ev=$(jget "$S" 'd["edmd"]["events"]')
from=$(jget "$S" 'd["edmd"].get("resumed_from_events", 0)')
echo "uninterrupted: $ev_ref events; resumed from event $from (time $(jget "$S" 'd["edmd"].get("resumed_from_time")')), $((ev - from)) events after the resume, $ev in all"
check resume_said_in_summary test "$(jget "$S" 'd["edmd"]["resumed"]')" = True
check resume_from_a_checkpoint test "${from:-0}" -gt 0
check resume_fewer_events_than_from_scratch test $((ev - from)) -lt "${ev_ref:-0}"
check resume_valid_packing test "$(jget "$S" '(d["count_placed"], d["pairs_below_delta_d"], d["termination_reason"] in ("pressure", "delta_phi"))')" = "($N, 0, True)"
"$PACKD" inspect "$T/r1/jobs/$J/result.h5" >"$T/inspect.json" 2>&1
check resume_said_in_file grep -q '"edmd/resumed": 1' "$T/inspect.json"
check resume_checkpoint_removed_when_done test ! -e "$CK"
