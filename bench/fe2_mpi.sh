#!/bin/sh
# bench/fe2_mpi.sh — evaluation rounds of an fe2 run over 1 and 2 MPI ranks:
# the thesis's block (examples/fe2/block-restricted-taylor.json: 3 × 3 Q1,
# 36 RVEs of 150 grains, restricted Taylor) over its side pressure and the
# first 0.2 mm ("short", 3 load steps) or 0.6 mm ("long", 7) of the push, its
# RVE packed once beforehand.  Runs `mpirun -np R packd run --threads 1`
# alternating R and the two lengths, REPS times; one line per run:
#   bench=fe2_mpi ranks=R rep=K push=short|long rounds=N steps_wall_s=W
#     cpu_s=C rank_cpu_s=C0,C1,… bytes_per_round=B load=L digest=D
#     (W the wall time of the load steps on rank 0, from the summary; C the
#     user+sys CPU of mpirun and every rank, /usr/bin/time, start-up
#     included; Cr each rank's own; B what rank 0 sent and received per round)
# then one line per R from the medians, per round at the margin
# ((long − short) / their difference in rounds: the start-up — MPI, the RVE,
# the result file — cancels):
#   bench=fe2_mpi ranks=R round_wall_ms=T round_cpu_ms=C (all processes)
#     busiest_rank_round_cpu_ms=K startup_cpu_s=S speedup=T1/TR (wall)
#     cpu_speedup=K1/KR (the busiest rank's CPU: the speedup on idle cores)
#     cpu_ratio=CR/C1 (the work MPI adds) same_digest=0|1 (per length)
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
j.pop("comment", None)
push = i["stages"][1]
for name, n in (("short", 2), ("long", 6)):  # 0.1 mm per increment
    i["stages"][0]["increments"] = 1
    i["stages"][1] = dict(push, increments=n, targets={"top": -0.1 * n})
    json.dump(j, open(name + ".json", "w"))
EOF
"$PACKD" run rve.json -o rve.h5 >/dev/null 2>rve.err || { cat rve.err; exit 1; }

k=1
while [ $k -le "$REPS" ]; do
    for r in $RANKS; do
        for len in short long; do
            load=$(cut -d' ' -f1 /proc/loadavg)
            rm -f cpu.*
            # each rank's CPU (its own /usr/bin/time, named by its rank)
            /usr/bin/time -f '%U %S' -o time.txt mpirun --allow-run-as-root --oversubscribe \
                -np "$r" sh -c 'exec /usr/bin/time -f "%U %S" -o cpu.${OMPI_COMM_WORLD_RANK:-0} "$@"' \
                sh "$PACKD" run "$len.json" -o "b$r.h5" --threads 1 --json >s.json 2>err.txt || {
                echo "bench=fe2_mpi ranks=$r rep=$k error=\"$(tail -n 3 err.txt | tr '\n"' ' _')\""
                exit 1
            }
            python3 - "$r" "$k" "$len" "$load" <<'EOF' | tee -a lines.txt
import glob, json, sys
r, k, length, load = sys.argv[1:]
s = json.load(open("s.json"))
u, y = map(float, open("time.txt").read().split()[-2:])
ranks = [sum(map(float, open(f).read().split()[-2:])) for f in sorted(glob.glob("cpu.*"))]
n = s["evaluation_rounds"]
b = s.get("mpi_bytes_sent", 0) + s.get("mpi_bytes_received", 0)
print(f"bench=fe2_mpi ranks={r} rep={k} push={length} rounds={n} "
      f"steps_wall_s={s['steps_wall_s']:.3f} cpu_s={u + y:.2f} "
      f"rank_cpu_s={','.join(f'{c:.2f}' for c in ranks)} bytes_per_round={b // n} "
      f"load={load} digest={s['result_digest'][:16]}")
EOF
        done
    done
    k=$((k + 1))
done

python3 - <<'EOF'
import statistics as st
rows = [dict(f.split("=", 1) for f in l.split()) for l in open("lines.txt")]
def med(r, length, f):
    return st.median(f(x) for x in rows if x["ranks"] == r and x["push"] == length)
def margin(r, f):  # ms per round between the short and the long push
    dn = med(r, "long", lambda x: int(x["rounds"])) - med(r, "short", lambda x: int(x["rounds"]))
    return 1e3 * (med(r, "long", f) - med(r, "short", f)) / dn
wall = lambda x: float(x["steps_wall_s"])
cpu = lambda x: float(x["cpu_s"])
busiest = lambda x: max(map(float, x["rank_cpu_s"].split(",")))
ranks = sorted({x["ranks"] for x in rows}, key=int)
same = len({(x["push"], x["digest"]) for x in rows}) == 2
w1, c1, b1 = (margin(ranks[0], f) for f in (wall, cpu, busiest))
for r in ranks:
    w, c, b = (margin(r, f) for f in (wall, cpu, busiest))
    n = med(r, "short", lambda x: int(x["rounds"]))
    print(f"bench=fe2_mpi ranks={r} round_wall_ms={w:.1f} round_cpu_ms={c:.1f} "
          f"busiest_rank_round_cpu_ms={b:.1f} startup_cpu_s={med(r, 'short', cpu) - c * n / 1e3:.2f} "
          f"speedup={w1 / w:.3f} cpu_speedup={b1 / b:.3f} cpu_ratio={c / c1:.3f} "
          f"same_digest={int(same)}")
EOF
