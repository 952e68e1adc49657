#!/bin/sh
# test_slurm.sh — the Slurm executor (daemon/executor_slurm.c) against a real
# one-node Slurm on loopback (slurm_cluster.inc: munged, slurmctld, slurmd,
# configs under $T, stopped by PID at the end):
#   - examples through Slurm give the digests of tests/data/example-digests.txt
#     (what the local executor and `packd run` give);
#   - an fe2 job asking for 2 MPI ranks: 2 Slurm tasks (srun --mpi=pmix), the
#     digest of `packd run --threads 1`; a rank killed -9: failed, naming it;
#   - a running job is in squeue, and in the jobcomp record after;
#   - DELETE of a running job: scancel, gone from squeue within 5 s;
#   - kill -9 of the daemon and restart: the running Slurm job is adopted,
#     never submitted twice;
#   - controller stopped: jobs stay accepted, /healthz says degraded; back:
#     the job runs;
#   - what Slurm is given (name, CPUs, time with the TERM margin, memory,
#     --requeue, TERM 60 s before the limit, srun packd run); TERM reaches
#     the worker, which keeps its partial result;
#   - one poll cycle for all jobs: one squeue, at most one queue transaction;
#   - preemption by the higher-priority partition: requeued, attempt 2
#     resumes the EDMD run from its checkpoint;
#   - node loss (slurmd and the job's processes killed -9, node down, slurmd
#     back): requeued, attempt 2 gives the uninterrupted run's digest;
#   - a job directory the node cannot see: failed, naming the node.
# slurmd runs in a mount namespace where $T/hidden is an empty tmpfs.
# Bounded: every wait is on a condition with a deadline; the EXIT trap stops
# the Slurm daemons by PID on any exit.  Runs in `make test` only: under the
# sanitizers (make sanitize) its cluster scenarios, ~7 min unsanitized, would
# put .ci/run past its time budget.
case ${PACKD_BUILD:-} in
*build-san*)
    echo "SKIP slurm: runs in make test; not repeated under the sanitizers (time budget of .ci/run)"
    exit 0
    ;;
esac
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
. "$SRC/tests/integration/slurm_cluster.inc"

mkdir -p "$T/hidden"
SLURMD_HIDE="$T/hidden"
trap 'slurm_cluster_stop; cleanup' EXIT # set first: a start cut short stops what it started
slurm_cluster_start
rc=$?
if [ $rc -eq 77 ]; then
    skip slurm "$SLURM_SKIP"
    exit 0
fi
if [ $rc -ne 0 ]; then
    fail slurm_cluster_starts "$(tail -3 "$T/slurm/slurmctld.log" "$T/slurm/slurmd.log" 2>/dev/null)"
    exit 1
fi
pass slurm_cluster_starts

printf 'executor = slurm\nworkers = 1\ncheckpoint_interval_s = 0.5\nslurm_mem_mb = 500\n' >"$T/slurm.conf"

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
#    (checkpoints at their default interval: none is due in these runs; an
#    EDMD run that saves one continues a re-based trajectory, not bit-identical)
printf 'workers = 2\n' >"$T/local.conf"
printf 'executor = slurm\n' >"$T/slurm-ex.conf"
start_daemon l1 --config "$T/local.conf" || { fail local_serve_starts; exit 1; }
BL=$B LPID=$DPID
start_daemon e1 --config "$T/slurm-ex.conf" || { fail serve_starts; exit 1; }
EPID=$DPID
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
    sh "$SRC/tests/tools/h5digest.sh" "$T/e1/jobs/$id/result.h5" | grep -v checkpoints_saved >"$T/$ex.dig"
    sh "$SRC/tests/tools/h5digest.sh" "$T/l1/jobs/$lid/result.h5" | grep -v checkpoints_saved >"$T/$ex.ref"
    check "slurm_example_${ex}_same_digests_as_local" sh -c "[ -s '$T/$ex.ref' ] && diff '$T/$ex.ref' '$T/$ex.dig' >/dev/null"
    check "slurm_example_${ex}_one_slurm_job" test "$(n_slurm_jobs "$id")" = 1
    LAST=$id
done
check slurm_jobcomp_records grep -q "Name=packd-$LAST " "$T/slurm/jobcomp.txt"
kill "$LPID" "$EPID"
wait "$LPID" "$EPID" 2>/dev/null
start_daemon d1 --config "$T/slurm.conf" || { fail serve_starts; exit 1; }

# 1b. fe2 over MPI ranks: a job asking for inputs.parallel.mpi_ranks = 2 is one
#     Slurm job of 2 tasks (srun --mpi=pmix) and gives the digest of `packd run
#     --threads 1`; in a second one (a long push), rank 1 killed -9 after a
#     converged load step: the job fails naming the rank, within seconds
python3 - "$SRC/tests/data/fe2/block-small.json" "$T" <<'PY'
import json, copy, sys
job = json.load(open(sys.argv[1]))  # test_fe2_mpi's block
job["inputs"]["output"]["micro_states"] = [0, 5, 15]  # 15: on rank 1
job["inputs"]["parallel"] = {"mpi_ranks": 2}
json.dump({"inputs": job["inputs"]}, open(sys.argv[2] + "/fe2.body", "w"))
k = copy.deepcopy(job["inputs"])
k["mesh"]["rectangle"]["elements"] = [3, 3]
k["stages"][1] = {"name": "push", "increments": 3000, "targets": {"top_y": -0.2}}
json.dump({"inputs": k}, open(sys.argv[2] + "/fe2-kill.body", "w"))
PY
submit_fe2() { c -o "$T/submit.json" -H 'Content-Type: application/json' --data-binary "@$1" \
    "$B/processes/fe2/execution" && member "$T/submit.json" jobID; }
if "$PACKD" run --help 2>&1 | grep -q 'built without MPI'; then
    skip slurm_fe2_ranks "this packd was built without MPI (install libopenmpi-dev, make again)"
else
    M=$(submit_fe2 "$T/fe2.body")
    MK=$(submit_fe2 "$T/fe2-kill.body")
    converged() { grep -qE '"stage":"fe2".*"done":[1-9]' "$T/d1/jobs/$MK/progress.jsonl" 2>/dev/null; }
    check slurm_fe2_ranks_job_runs wait_for 120 converged
    MKJ=$(squeue -h -n "packd-$MK" -o %i)
    # scontrol listpids: PID JOBID STEPID LOCALID GLOBALID; step 0 is srun's, GLOBALID the rank
    victim=$(scontrol listpids "$MKJ" | awk '$3 == "0" && $5 == "1" {print $1}')
    t0=$(date +%s%N)
    kill -9 $victim
    check slurm_fe2_lost_rank_fails wait_status "$MK" failed 30
    echo "rank 1 of 2 killed (pid $victim): failed after $((($(date +%s%N) - t0) / 1000000)) ms: $(member "$T/st.json" message)"
    check slurm_fe2_lost_rank_named grep -q '"message": "failed: .*MPI rank 1 of 2' "$T/st.json"
    if wait_status "$M" successful 120; then
        MS="$T/d1/jobs/$M/summary.json"
        # the reference: the same job file (the daemon adds the operator's wall-time
        # limit to the inputs the digest covers), one process, one thread
        "$PACKD" run "$T/d1/jobs/$M/job.json" -o "$T/fe2-ref.h5" --threads 1 --json \
            >"$T/fe2-ref.json" 2>/dev/null
        # (the digest covers every dataset: test_fe2_mpi compares them one by one)
        check slurm_fe2_two_ranks test "$(jget "$MS" 'd["mpi_ranks"]')" = 2
        check slurm_fe2_two_slurm_tasks grep -q "Name=packd-$M .* ProcCnt=2 " "$T/slurm/jobcomp.txt"
        ref=$(jget "$T/fe2-ref.json" 'd["result_digest"]') got=$(jget "$MS" 'd["result_digest"]')
        check slurm_fe2_ranks_digest_of_threads_1 sh -c "[ -n '$ref' ] && [ '$ref' = '$got' ]"
    else
        fail slurm_fe2_ranks_job "status $(status_of "$M"): $(member "$T/st.json" message)"
    fi
fi

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

# 6. what Slurm was given: name, CPUs, time (limit + the TERM margin),
#    memory, --requeue, TERM 60 s before the limit, srun packd run
slow_body 30 >"$T/slow30.body"
J=$(submit "$T/slow30.body")
wait_for 60 in_squeue "$J" RUNNING
scontrol show job -o "$(squeue -h -n "packd-$J" -o %i)" >"$T/sc.txt"
for kv in "JobName=packd-$J" NumCPUs=1 TimeLimit=00:02:00 Requeue=1 MinMemoryNode=500M \
    "Command=$T/d1/jobs/$J/slurm.sh"; do
    check "slurm_job_has_$(echo "$kv" | cut -d= -f1)" grep -q " $kv " "$T/sc.txt"
done
check slurm_script_term_before_limit grep -qx '#SBATCH --signal=TERM@60' "$T/d1/jobs/$J/slurm.sh"
case $PACKD in /*) packd_abs=$PACKD ;; *) packd_abs=$PWD/$PACKD ;; esac
check slurm_script_srun_packd_run grep -q "^srun .*'$packd_abs' run job.json" "$T/d1/jobs/$J/slurm.sh"
# the signal Slurm sends at TimeLimit - 60 s (to the steps: srun forwards it)
# stops the worker, which keeps what it placed (sent once the worker reports)
reporting() { [ "$(wc -l 2>/dev/null <"$T/d1/jobs/$1/progress.jsonl")" -ge 2 ] 2>/dev/null; }
wait_for 60 reporting "$J"
scancel -s TERM "$(squeue -h -n "packd-$J" -o %i)"
wait_status "$J" failed 60
echo "TERM: $(member "$T/st.json" message)"
check slurm_term_reaches_worker grep -q '"message": "failed: .*cancel' "$T/st.json"
check slurm_term_partial_result test -s "$T/d1/jobs/$J/result.h5"

# 7. one poll cycle for all jobs: one squeue (counted by a wrapper on PATH
#    that runs the real one) and at most one queue transaction per cycle,
#    while three EDMD jobs run and report progress every 0.5 s
N=3000 L=14
jam_body $N $L >"$T/jam.body"
mkdir -p "$T/shim"
real_squeue=$(command -v squeue)
printf '#!/bin/sh\necho x >>"%s"\nexec "%s" "$@"\n' "$T/squeue.calls" "$real_squeue" >"$T/shim/squeue"
chmod +x "$T/shim/squeue"
kill "$DPID"
wait "$DPID" 2>/dev/null
PATH="$T/shim:$PATH" start_daemon d1 --config "$T/slurm.conf" || { fail serve_restarts; exit 1; }
P1=$(submit "$T/jam.body")
P2=$(submit "$T/jam.body")
P3=$(submit "$T/jam.body")
all_running() { for j in $P1 $P2 $P3; do status_of "$j" | grep -qx running || return 1; done; }
check slurm_three_running wait_for 90 all_running
metric() { c "$B/metrics" | awk -v m="$1" '$1 == m {print $2}'; }
calls() { wc -l <"$T/squeue.calls"; }
percent() { c "$B/jobs/$1" | sed -n 's/^  "progress": \([0-9]*\).*/\1/p'; }
cy0=$(metric packd_executor_poll_cycles_total) tx0=$(metric packd_queue_transactions_total)
sq0=$(calls) pr0=$(percent "$P1")
five_more() { [ "$(metric packd_executor_poll_cycles_total)" -ge $((cy0 + 5)) ]; }
wait_for 30 five_more
cy1=$(metric packd_executor_poll_cycles_total) tx1=$(metric packd_queue_transactions_total)
sq1=$(calls) pr1=$(percent "$P1")
s1=$(metric packd_executor_poll_seconds_total)
echo "poll: $((cy1 - cy0)) cycles, $((sq1 - sq0)) squeue calls, $((tx1 - tx0)) transactions; progress $pr0 -> $pr1 %; $(awk "BEGIN{printf \"%.1f\", 1000*$s1/$cy1}") ms per cycle on average"
check slurm_poll_one_squeue_per_cycle test $((sq1 - sq0)) -le $((cy1 - cy0 + 1))
check slurm_poll_one_transaction_per_cycle test $((tx1 - tx0)) -le $((cy1 - cy0 + 1))
check slurm_poll_progress_reaches_client test "${pr1:-0}" -gt "${pr0:-0}"
for j in $P1 $P2 $P3; do c -X DELETE -o /dev/null "$B/jobs/$j"; done
for j in $P1 $P2 $P3; do wait_for 10 not_live "$j"; done

# 8. preemption: a job of the higher-priority partition takes the node's
#    4 CPUs; Slurm requeues the EDMD job, which resumes from its checkpoint
E=$(submit "$T/jam.body")
checkpointed() { [ -s "$T/d1/jobs/$E/checkpoint.h5" ] && in_squeue "$E" RUNNING; }
check slurm_preempt_checkpoint_before wait_for 120 checkpointed
sbatch -Q -p high -n 4 -o /dev/null --wrap 'sleep 2' >/dev/null
# a requeued job may be held 120 s (BeginTime), then waits for a scheduling pass
requeued() { status_of "$E" >/dev/null; grep -q 'attempt 2' "$T/st.json"; }
check slurm_preempt_requeued_attempt_2 wait_for 300 requeued
echo "after preemption: $(member "$T/st.json" status): $(member "$T/st.json" message)"
check slurm_preempt_job_finishes wait_status "$E" successful 240
SUM="$T/d1/jobs/$E/summary.json"
echo "preempted job: resumed $(jget "$SUM" 'd["edmd"].get("resumed")') from event $(jget "$SUM" 'd["edmd"].get("resumed_from_events")') of $(jget "$SUM" 'd["edmd"]["events"]')"
check slurm_preempt_resumed_from_checkpoint test "$(jget "$SUM" 'd["edmd"].get("resumed_from_events", 0) > 0')" = True
check slurm_preempt_valid_packing test "$(jget "$SUM" '(d["count_placed"], d["pairs_below_delta_d"], d["termination_reason"] in ("pressure", "delta_phi"))')" = "($N, 0, True)"
check slurm_preempt_one_slurm_job test "$(n_slurm_jobs "$E")" = 1

# 9. node loss: slurmd and every process of the running job killed -9 (as
#    a crashed node); the controller marks the node down and requeues the
#    job; slurmd back: attempt 2 runs to the end with the digest of an
#    uninterrupted `packd run` (checkpoints off: a resumed EDMD trajectory
#    is a continuation, not bit-identical)
printf 'executor = slurm\ncheckpoint_interval_s = 1000\n' >"$T/nocheckpoint.conf"
start_daemon n1 --config "$T/nocheckpoint.conf" || { fail serve_n1_starts; exit 1; }
python3 -c "import json,sys; print(json.dumps({'process': 'pack', **json.load(open(sys.argv[1]))}))" \
    "$T/jam.body" >"$T/jam-job.json"
# the reference with the workers' flags (a checkpoint file named, none due)
"$PACKD" run "$T/jam-job.json" -o "$T/jam-ref.h5" --threads 1 --checkpoint "$T/jam-ref.ck" \
    --checkpoint-interval 1000 >/dev/null 2>&1 &
ref=$!
F=$(submit "$T/jam.body")
started() { in_squeue "$F" RUNNING && [ "$(wc -l 2>/dev/null <"$T/n1/jobs/$F/progress.jsonl")" -ge 2 ] 2>/dev/null; }
check slurm_nodeloss_job_started wait_for 120 started
FJ=$(squeue -h -n "packd-$F" -o %i)
pids=$(scontrol listpids "$FJ" | awk 'NR > 1 {print $1}')
steps=$(for p in $pids; do ps -o ppid= -p "$p"; done | sort -u)
slurmd_kill
kill -9 $pids $steps 2>/dev/null
node_down() { sinfo -h -o %T | grep -q down; }
check slurm_nodeloss_node_down wait_for 120 node_down
slurmd_start
# Slurm holds a requeued job for 120 s (BeginTime) before it may start again
requeued_accepted() { [ "$(status_of "$F")" = accepted ] && grep -q 'requeued after attempt 1' "$T/st.json"; }
check slurm_nodeloss_accepted_while_requeued wait_for 60 requeued_accepted
echo "node lost: $(member "$T/st.json" message)"
again() { status_of "$F" >/dev/null; grep -q 'attempt 2' "$T/st.json"; }
check slurm_nodeloss_requeued_attempt_2 wait_for 300 again
echo "after node loss: $(member "$T/st.json" message)"
check slurm_nodeloss_job_finishes wait_status "$F" successful 240
wait "$ref"
sh "$SRC/tests/tools/h5digest.sh" "$T/jam-ref.h5" | grep -v checkpoints_saved >"$T/jam.ref"
sh "$SRC/tests/tools/h5digest.sh" "$T/n1/jobs/$F/result.h5" | grep -v checkpoints_saved >"$T/jam.dig"
check slurm_nodeloss_same_digest sh -c "[ -s '$T/jam.ref' ] && diff '$T/jam.ref' '$T/jam.dig'"
check slurm_nodeloss_one_slurm_job test "$(n_slurm_jobs "$F")" = 1

# 10. a job directory the node cannot see: failed, naming the node
start_daemon hidden/d2 --config "$T/slurm.conf" || { fail serve_hidden_starts; exit 1; }
H=$(submit "$T/fast.json")
wait_status "$H" failed 60
echo "hidden directory: $(member "$T/st.json" message)"
check slurm_invisible_dir_fails_naming_node grep -q "not visible on node $SLURM_HOST" "$T/st.json"
