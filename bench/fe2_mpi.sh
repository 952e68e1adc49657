#!/bin/sh
# bench/fe2_mpi.sh — evaluation rounds of an fe2 run over 1 and 2 MPI ranks:
# the thesis's block (examples/fe2/block-restricted-taylor.json: 3 × 3 Q1,
# 36 RVEs of 150 grains, restricted Taylor) over its side pressure and the
# first 0.4 mm of the push (5 load steps), its RVE packed once beforehand.
# Runs `mpirun -np R packd run --threads 1` alternating R = 1, 2, … REPS
# times and prints one line per run, then one per R (medians):
#   bench=fe2_mpi ranks=R rep=K rounds=N steps_wall_s=W round_wall_ms=W/N
#     cpu_s=C cpu_per_round_ms=C/N bytes_per_round=B load=L digest=D
#     rank_cpu_s=C0,C1,… critical_cpu_per_round_ms=max(Cr)/N
#     (W the wall time of the load steps on rank 0, from the summary; C the
#     user+sys CPU of mpirun and every rank, /usr/bin/time, the start-up
#     included; Cr each rank's own; B what rank 0 sent and received per round)
#   bench=fe2_mpi ranks=R median_round_wall_ms=… median_cpu_per_round_ms=…
#     median_critical_cpu_per_round_ms=… speedup=T1/TR (wall)
#     cpu_speedup=K1/KR (the busiest rank's CPU: the speedup on idle cores,
#     waits aside) cpu_ratio=CR/C1 (the work MPI adds) same_digest=0|1
# load= is the 1-minute load average when the run started (the machine is
# shared: wall figures only compare at a similar load).
# PACKD (build/packd), PACKD_BENCH_REPS (3), PACKD_BENCH_RANKS ("1 2").
set -u
PACKD=${PACKD:-build/packd}
case "$PACKD" in /*) ;; *) PACKD="$PWD/$PACKD" ;; esac
SRC=$(cd "$(dirname "$0")/.." && pwd)
REPS=${PACKD_BENCH_REPS:-3}
RANKS=${PACKD_BENCH_RANKS:-1 2}
command -v mpirun >/dev/null || { echo "bench=fe2_mpi error=\"mpirun not installed (openmpi-bin)\""; exit 1; }
"$PACKD" run --help | grep -q 'built with MPI' ||
    { echo "bench=fe2_mpi error=\"packd built without MPI\""; exit 1; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1

python3 - "$SRC/examples/fe2/block-restricted-taylor.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
i = j["inputs"]
json.dump({"process": "pack", "inputs": i["micro"]["rve"]["pack"]}, open("rve.json", "w"))
i["micro"]["rve"] = {"file": "rve.h5"}
i["stages"] = [dict(i["stages"][0], increments=1),
               dict(i["stages"][1], increments=4, targets={"top": -0.4})]
j.pop("comment", None)
json.dump(j, open("block.json", "w"))
EOF
"$PACKD" run rve.json -o rve.h5 >/dev/null 2>rve.err || { cat rve.err; exit 1; }

k=1
while [ $k -le "$REPS" ]; do
    for r in $RANKS; do
        load=$(cut -d' ' -f1 /proc/loadavg)
        rm -f cpu.*
        # each rank's CPU (its own /usr/bin/time, named by its rank)
        /usr/bin/time -f '%U %S' -o time.txt mpirun --allow-run-as-root --oversubscribe -np "$r" \
            sh -c 'exec /usr/bin/time -f "%U %S" -o cpu.${OMPI_COMM_WORLD_RANK:-0} "$@"' sh \
            "$PACKD" run block.json -o "b$r.h5" --threads 1 --json >s.json 2>err.txt ||
            { echo "bench=fe2_mpi ranks=$r rep=$k error=\"$(tail -n 3 err.txt | tr '\n"' ' _')\""; exit 1; }
        python3 - "$r" "$k" "$load" <<'EOF' | tee -a lines.txt
import json, sys
r, k, load = sys.argv[1:]
s = json.load(open("s.json"))
import glob
u, y = map(float, open("time.txt").read().split()[-2:])
ranks = [sum(map(float, open(f).read().split()[-2:])) for f in sorted(glob.glob("cpu.*"))]
n = s["evaluation_rounds"]
b = s.get("mpi_bytes_sent", 0) + s.get("mpi_bytes_received", 0)
print(f"bench=fe2_mpi ranks={r} rep={k} rounds={n} steps_wall_s={s['steps_wall_s']:.3f} "
      f"round_wall_ms={1e3 * s['steps_wall_s'] / n:.2f} cpu_s={u + y:.2f} "
      f"cpu_per_round_ms={1e3 * (u + y) / n:.2f} rank_cpu_s={','.join(f'{c:.2f}' for c in ranks)} "
      f"critical_cpu_per_round_ms={1e3 * max(ranks) / n:.2f} bytes_per_round={b // n} load={load} "
      f"digest={s['result_digest'][:16]}")
EOF
    done
    k=$((k + 1))
done
python3 - <<'EOF'
import statistics as st
rows = [dict(f.split("=", 1) for f in l.split()) for l in open("lines.txt")]
by = {}
for x in rows:
    by.setdefault(x["ranks"], []).append(x)
base = by[min(by, key=int)]
t1 = st.median(float(x["round_wall_ms"]) for x in base)
c1 = st.median(float(x["cpu_per_round_ms"]) for x in base)
k1 = st.median(float(x["critical_cpu_per_round_ms"]) for x in base)
digests = {x["digest"] for x in rows}
for r in sorted(by, key=int):
    t = st.median(float(x["round_wall_ms"]) for x in by[r])
    c = st.median(float(x["cpu_per_round_ms"]) for x in by[r])
    k = st.median(float(x["critical_cpu_per_round_ms"]) for x in by[r])
    print(f"bench=fe2_mpi ranks={r} median_round_wall_ms={t:.2f} median_cpu_per_round_ms={c:.2f} "
          f"median_critical_cpu_per_round_ms={k:.2f} speedup={t1 / t:.3f} "
          f"cpu_speedup={k1 / k:.3f} cpu_ratio={c / c1:.3f} same_digest={int(len(digests) == 1)}")
EOF
