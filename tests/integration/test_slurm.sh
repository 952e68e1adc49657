#!/bin/sh
# test_slurm.sh — the Slurm executor (daemon/executor_slurm.c) against a real
# one-node Slurm on loopback (slurm_cluster.inc: munged, slurmctld, slurmd,
# configs under $T, stopped by PID at the end):
#   - examples through Slurm give the digests of tests/data/example-digests.txt
#     (what the local executor and `packd run` give);
#   - a running job is in squeue, and in the jobcomp record after;
#   - DELETE of a running job: scancel, gone from squeue within 5 s;
#   - kill -9 of the daemon and restart: the running Slurm job is adopted,
#     never submitted twice;
#   - controller stopped: jobs stay accepted, /healthz says degraded; back:
#     the job runs;
#   - a job directory the node cannot see: failed, naming the node.
# slurmd runs in a mount namespace where $T/hidden is an empty tmpfs.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
. "$SRC/tests/integration/slurm_cluster.inc"

mkdir -p "$T/hidden"
SLURMD_HIDE="$T/hidden"
slurm_cluster_start
rc=$?
if [ $rc -eq 77 ]; then
    skip slurm "$SLURM_SKIP"
    exit 0
fi
trap 'slurm_cluster_stop; cleanup' EXIT
if [ $rc -ne 0 ]; then
    fail slurm_cluster_starts "$(tail -3 "$T/slurm/slurmctld.log" "$T/slurm/slurmd.log" 2>/dev/null)"
    exit 1
fi
pass slurm_cluster_starts

printf 'executor = slurm\nworkers = 1\ncheckpoint_interval_s = 0.5\n' >"$T/slurm.conf"

in_squeue() { # id [state]: the job is listed (in that state)
    squeue -h -t all -n "packd-$1" -o '%T' | grep -qx "${2:-.*}"
}
not_live() { # id: squeue lists no pending/running job of this name
    ! squeue -h -n "packd-$1" -o '%T' | grep -qE 'PENDING|RUNNING|CONFIGURING|COMPLETING'
}
n_slurm_jobs() { # id: how many Slurm jobs ever had this name (jobcomp + queue)
    squeue -h -t all -n "packd-$1" -o '%i' | sort -u | wc -l
}

# 1. examples: the same result digests through Slurm as through local workers
printf 'workers = 2\ncheckpoint_interval_s = 0.5\n' >"$T/local.conf"
start_daemon l1 --config "$T/local.conf" || { fail local_serve_starts; exit 1; }
BL=$B
start_daemon d1 --config "$T/slurm.conf" || { fail serve_starts; exit 1; }
IDS=""
for ex in meier-quartz-2d edmd-quartz-2d fuller-3d-periodic din-a16-3d-walled; do
    body_of "$SRC/examples/$ex.json" >"$T/$ex.body"
    id=$(submit "$T/$ex.body")
    lid=$(B=$BL submit "$T/$ex.body")
    IDS="$IDS $ex:$id:$lid"
done
for p in $IDS; do
    ex=${p%%:*}
    id=${p#*:}
    lid=${id#*:}
    id=${id%:*}
    if ! wait_status "$id" successful 120 || ! B=$BL wait_status "$lid" successful 120; then
        fail "slurm_example_$ex" "status $(status_of "$id"): $(member "$T/st.json" message)"
        continue
    fi
    # how many checkpoints a run saved counts wall-clock intervals: not a result
    sh "$SRC/tests/tools/h5digest.sh" "$T/d1/jobs/$id/result.h5" | grep -v checkpoints_saved >"$T/$ex.dig"
    sh "$SRC/tests/tools/h5digest.sh" "$T/l1/jobs/$lid/result.h5" | grep -v checkpoints_saved >"$T/$ex.ref"
    check "slurm_example_${ex}_same_digests_as_local" sh -c "[ -s '$T/$ex.ref' ] && diff '$T/$ex.ref' '$T/$ex.dig' >/dev/null"
    check "slurm_example_${ex}_one_slurm_job" test "$(n_slurm_jobs "$id")" = 1
    LAST=$id
done
check slurm_jobcomp_records grep -q "Name=packd-$LAST " "$T/slurm/jobcomp.txt"

# 2. a running job shows in squeue, its progress reaches the client
slow_body 8 >"$T/slow.body"
J=$(submit "$T/slow.body")
check slurm_running_job_in_squeue wait_for 60 in_squeue "$J" RUNNING
check slurm_running_status wait_status "$J" running 30
echo "running: $(member "$T/st.json" message)"
check slurm_running_message_names_node grep -q "running on Slurm node $SLURM_HOST" "$T/st.json"

# 3. DELETE: scancel, gone from squeue within 5 s
t0=$(date +%s%N)
c -X DELETE -o /dev/null "$B/jobs/$J"
check slurm_delete_scancels_within_5s wait_for 5 not_live "$J"
echo "DELETE -> not in squeue after $((($(date +%s%N) - t0) / 1000000)) ms"
check slurm_delete_dismissed wait_status "$J" dismissed 10

# 4. kill -9 of the daemon while Slurm runs a job; the restart adopts it
slow_body 6 >"$T/slow6.body"
K=$(submit "$T/slow6.body")
wait_for 60 in_squeue "$K" RUNNING
kill -9 "$DPID"
wait "$DPID" 2>/dev/null
check slurm_job_survives_daemon_kill in_squeue "$K" RUNNING
start_daemon d1 --config "$T/slurm.conf" || { fail serve_restarts; exit 1; }
wait_status "$K" failed 60
echo "adopted job: $(member "$T/st.json" status): $(member "$T/st.json" message)"
check slurm_adopted_job_ends_with_its_verdict grep -q '"message": "failed: ran out of wall time' "$T/st.json"
check slurm_adopted_no_duplicate test "$(n_slurm_jobs "$K")" = 1

# 5. controller stopped: accepted, degraded; back: runs
slurmctld_stop
A=$(submit "$T/fast.json")
health_degraded() { c "$B/healthz" | grep -q '"state": "degraded"'; }
check slurm_controller_down_health_degraded wait_for 30 health_degraded
sleep_cycle() { status_of "$A" >/dev/null && grep -q 'waiting for the Slurm controller\|"status": "accepted"' "$T/st.json"; }
check slurm_controller_down_job_accepted sleep_cycle
echo "controller down: $(member "$T/st.json" message); healthz $(c "$B/healthz" | tr -d '\n ' | head -c 300)"
slurmctld_start
check slurm_controller_back_job_runs wait_status "$A" successful 90
health_ok() { c "$B/healthz" | grep -q '"state": "ok"'; }
check slurm_controller_back_health_ok wait_for 30 health_ok

# 6. a job directory the node cannot see: failed, naming the node
start_daemon hidden/d2 --config "$T/slurm.conf" || { fail serve_hidden_starts; exit 1; }
H=$(submit "$T/fast.json")
wait_status "$H" failed 60
echo "hidden directory: $(member "$T/st.json" message)"
check slurm_invisible_dir_fails_naming_node grep -q "not visible on node $SLURM_HOST" "$T/st.json"
