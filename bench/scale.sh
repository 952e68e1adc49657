#!/bin/sh
# bench/scale.sh — queue throughput of the Slurm executor against local
# workers, on a real one-node Slurm on loopback (tests/integration/
# slurm_cluster.inc; the node declares 4 CPUs).  One line per case:
#   bench=scale case=NAME key=value ...
# Cases:
#   sbatch        20 `sbatch --wrap true` calls, one after the other: wall ms per call
#                 (what the daemon pays per submission) and submit -> start latency
#   jobs_local    N small jobs (Meier's 2D quartz sand, ~0.2 s each) through 4 local
#                 workers: wall s until all are successful, jobs/s
#   jobs_slurm    the same N jobs through the Slurm executor (4 CPUs): jobs/s, the
#                 overhead per job = (wall_slurm - wall_local) * 4 / N (4 run at a time),
#                 the poll cycle's mean wall ms (/metrics) and queue transactions per job
# N = 200 (BENCH_SCALE_JOBS).  Wall times on a shared machine: compare the two
# cases of one run, not runs of different days.
# Usage: PACKD=build/packd sh bench/scale.sh
PACKD_SRC=${PACKD_SRC:-$(pwd)}
. "$PACKD_SRC/tests/integration/serve_helpers.inc"
. "$SRC/tests/integration/slurm_cluster.inc"
N=${BENCH_SCALE_JOBS:-200}
out() { echo "bench=scale $*"; }
now_ms() { echo $(($(date +%s%N) / 1000000)); }

trap 'slurm_cluster_stop; cleanup' EXIT
slurm_cluster_start
rc=$?
[ $rc -eq 77 ] && { echo "bench=scale skipped: $SLURM_SKIP"; exit 0; }
[ $rc -eq 0 ] || { echo "bench=scale: the Slurm cluster did not start"; exit 1; }

# sbatch: the submission call alone, and submit -> RUNNING/COMPLETED latency
t0=$(now_ms)
for k in $(seq 20); do sbatch -Q -o /dev/null --wrap true >/dev/null; done
t1=$(now_ms)
done_all() { [ -z "$(squeue -h -o %i)" ]; }
wait_for 120 done_all
t2=$(now_ms)
out "case=sbatch calls=20 ms_per_call=$(((t1 - t0) / 20)) ms_until_all_completed=$((t2 - t0))"

# N jobs through one daemon: sets WALL_MS, from the first submission to the last end
run_jobs() { # name config
    start_daemon "$1" --config "$2" >/dev/null || return 1
    t0=$(now_ms)
    for k in $(seq "$N"); do submit "$T/fast.json" >/dev/null; done
    all_ended() {
        c -o "$T/list.json" "$B/jobs?limit=1000&status=successful" &&
            [ "$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['numberMatched'])" "$T/list.json" 2>/dev/null)" = "$N" ]
    }
    wait_for 1200 all_ended || { echo "bench=scale: $1 did not finish"; return 1; }
    WALL_MS=$(($(now_ms) - t0))
}
metric() { c "$B/metrics" | awk -v m="$1" '$1 == m {print $2}'; }
printf 'workers = 4\n' >"$T/local.conf"
run_jobs local "$T/local.conf" || exit 1
wl=$WALL_MS
out "case=jobs_local jobs=$N wall_s=$(awk "BEGIN{printf \"%.1f\", $wl/1000}") jobs_per_s=$(awk "BEGIN{printf \"%.2f\", $N*1000/$wl}") transactions_per_job=$(awk "BEGIN{printf \"%.1f\", $(metric packd_queue_transactions_total)/$N}")"
kill "$DPID"
printf 'executor = slurm\nworkers = 0\n' >"$T/slurm.conf"
run_jobs slurm "$T/slurm.conf" || exit 1
ws=$WALL_MS
cy=$(metric packd_executor_poll_cycles_total)
cs=$(metric packd_executor_poll_seconds_total)
out "case=jobs_slurm jobs=$N wall_s=$(awk "BEGIN{printf \"%.1f\", $ws/1000}") jobs_per_s=$(awk "BEGIN{printf \"%.2f\", $N*1000/$ws}") overhead_s_per_job=$(awk "BEGIN{printf \"%.2f\", ($ws-$wl)*4/1000/$N}") poll_cycles=$cy poll_ms_per_cycle=$(awk "BEGIN{printf \"%.1f\", 1000*$cs/$cy}") transactions_per_job=$(awk "BEGIN{printf \"%.1f\", $(metric packd_queue_transactions_total)/$N}")"
