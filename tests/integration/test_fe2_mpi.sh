#!/bin/sh
# test_fe2_mpi.sh — an fe2 run over MPI ranks (api/fe2/fe2_mpi.h) with Debian's
# real mpirun: `mpirun -np 2` and `-np 3 --threads 2` of `packd run` on a
# reduced block (2 × 2 Q1, 16 Gauss points, 40-grain Taylor RVE, 3 load steps)
# write the same datasets, bit for bit, as `packd run --threads 1`, with the
# same result digest, and the file passes its audit (stored digest, H5MD
# rules); one rank killed (-9) mid-run ends the run failed within seconds —
# the reason names the rank and its Gauss points, the converged steps are
# kept, the file says incomplete; rank 0 killed leaves no result nor
# summary — never a hang nor a successful-looking result.  A packd built without MPI refuses a launch of several ranks.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$(pwd)}
case "$PACKD" in /*) ;; *) PACKD="$PWD/$PACKD" ;; esac
. "$SRC/tests/integration/check.inc"
T=$(mktemp -d)
MPIRUN_PID=""
trap '[ -n "$MPIRUN_PID" ] && kill -9 "$MPIRUN_PID" 2>/dev/null; rm -rf "$T"' EXIT
cd "$T" || exit 1

python3 - "$SRC/tests/data/fe2/block-small.json" <<'EOF'
import json, copy, sys
job = json.load(open(sys.argv[1]))  # test_fe2.sh's block
# an output RVE on another rank (15: rank 1 of 2, rank 2 of 3): its centres travel
job["inputs"]["output"]["micro_states"] = [0, 5, 15]
json.dump(job, open("job.json", "w"))
# a long push (3000 small increments, 36 Gauss points; every one converges,
# ~8 s of CPU): killed long before its end
k = copy.deepcopy(job)
k["inputs"]["mesh"]["rectangle"]["elements"] = [3, 3]
k["inputs"]["stages"][1] = {"name": "push", "increments": 3000, "targets": {"top_y": -0.2}}
json.dump(k, open("kill.json", "w"))
EOF

if "$PACKD" run --help 2>&1 | grep -q 'built without MPI'; then
    # the launcher's environment of a second rank: refused, not run twice
    OMPI_COMM_WORLD_SIZE=2 "$PACKD" run job.json -o x.h5 >x.out 2>x.err
    rc=$?
    check mpi_absent_refuses_ranks sh -c "[ $rc -eq 2 ] && [ ! -e x.h5 ] &&
        grep -q 'built without MPI' x.err && grep -q 'libopenmpi-dev' x.err"
    skip fe2_mpi_ranks "this packd was built without MPI (install libopenmpi-dev, make again)"
    exit 0
fi
if ! command -v mpirun >/dev/null 2>&1; then
    skip fe2_mpi_ranks "mpirun not installed (Debian's openmpi-bin)"
    exit 0
fi
# under make sanitize: Open MPI's allocations that outlive MPI_Finalize are not
# packd's leaks (tests/sanitizer/openmpi.supp); the slow unwinder reaches the
# library's frames, which are built without frame pointers
export LSAN_OPTIONS="suppressions=$SRC/tests/sanitizer/openmpi.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export ASAN_OPTIONS="fast_unwind_on_malloc=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
# root needs --allow-run-as-root; 3 ranks on a 2-core machine need --oversubscribe
MPIRUN="mpirun --allow-run-as-root --oversubscribe"

"$PACKD" run job.json -o s.h5 --threads 1 --json >s.json 2>s.err ||
    { fail fe2_mpi_serial_reference "$(cat s.err)"; exit 1; }
sh "$SRC/tests/tools/h5digest.sh" s.h5 >s.dig

# ranks R, threads per rank: the same bits as one process with one thread
for rt in 2:1 3:2; do
    r=${rt%:*}
    th=${rt#*:}
    timeout 180 $MPIRUN -np "$r" "$PACKD" run job.json -o "m$r.h5" --threads "$th" --json \
        >"m$r.json" 2>"m$r.err"
    rc=$?
    check "fe2_mpi_np${r}_completes" sh -c "[ $rc -eq 0 ] && python3 -c \"
import json; s = json.load(open('m$r.json')); r = json.load(open('s.json'))
assert s['complete'] and s['mpi_ranks'] == $r and s['threads'] == $th, s
assert s['steps'] == r['steps'] == 3 and s['gauss_points'] == 16, s
assert s['result_digest'] == r['result_digest'], (s['result_digest'], r['result_digest'])\"" ||
        sed 's/^/  /' "m$r.err"
    sh "$SRC/tests/tools/h5digest.sh" "m$r.h5" >"m$r.dig"
    check "fe2_mpi_np${r}_datasets_bit_identical" sh -c \
        "[ \$(wc -l <s.dig) -ge 50 ] && grep -q 'micro/gauss_point_15/value' s.dig &&
        ! grep -q unreadable s.dig && cmp -s s.dig m$r.dig" ||
        diff s.dig "m$r.dig" | head -5
    check "fe2_mpi_np${r}_result_audited" sh -c "\"$PACKD\" inspect m$r.h5 | python3 -c \"
import json, sys; i = json.load(sys.stdin)
assert i['result_digest_verified'] is True, i.get('result_digest')\" &&
        python3 \"$SRC/tests/tools/h5md_check.py\" m$r.h5 >/dev/null"
done

# one rank killed (-9) mid-run, after a converged load step: sets rc (of
# mpirun), dt (seconds from the kill to its end), victim ("" if not found)
kill_rank() { # rank, output prefix
    timeout 120 $MPIRUN -np 3 "$PACKD" run "$T/kill.json" -o "$2.h5" --json --progress-fd 2 \
        >"$2.json" 2>"$2.err" &
    MPIRUN_PID=$!
    i=0 # bounded: 60 s
    while ! grep -qE '"stage":"fe2".*"done":[1-9]' "$2.err" 2>/dev/null &&
        kill -0 $MPIRUN_PID 2>/dev/null && [ $i -lt 600 ]; do
        sleep 0.1
        i=$((i + 1))
    done
    victim=""
    for p in $(pgrep -f "$T/kill.json"); do
        tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$1" && victim=$p
    done
    [ -n "$victim" ] || { kill -9 $MPIRUN_PID; wait $MPIRUN_PID; MPIRUN_PID=""; return 1; }
    t0=$(date +%s.%N)
    kill -9 "$victim"
    wait $MPIRUN_PID
    rc=$?
    MPIRUN_PID=""
    dt=$(awk "BEGIN { print $(date +%s.%N) - $t0 }")
    echo "killed rank $1 (pid $victim): mpirun ended with $rc after $dt s"
}
fast_end() { [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && awk "BEGIN { exit !($dt < 30) }"; }

# rank 2: rank 0 names it, keeps the converged steps, marks the file incomplete
if ! kill_rank 2 k2; then
    fail fe2_mpi_rank_killed "rank 2 not found running (progress: $(tail -c 300 k2.err))"
else
    check fe2_mpi_rank_killed_ends_failed_fast fast_end
    # the reason on stderr (stdout's long JSON summary can be cut by mpirun,
    # which stops forwarding once it has killed the ranks)
    check fe2_mpi_rank_killed_reason_names_rank sh -c "grep 'packd run: failed' k2.err |
        grep -q 'MPI rank 2 of 3 (Gauss points 24..35)'"
    grep 'failed' k2.err | grep -v '"stage"' | head -2 | sed 's/^/  /'
    check fe2_mpi_rank_killed_file_incomplete sh -c "
        h5dump -d /observables/verdict/complete k2.h5 | grep -q '(0): 0' &&
        h5dump -d /observables/fe2/termination_reason k2.h5 | grep -q 'rank_lost'"
fi
# rank 0 (the writer): the launch ends, no result file, no summary
if ! kill_rank 0 k0; then
    fail fe2_mpi_rank0_killed "rank 0 not found running (progress: $(tail -c 300 k0.err))"
else
    check fe2_mpi_rank0_killed_ends_fast fast_end
    check fe2_mpi_rank0_killed_no_result sh -c "[ ! -s k0.json ] && [ ! -e k0.h5 ]"
fi
