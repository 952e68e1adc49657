#!/bin/sh
# run_examples.sh — run the FE² examples of examples/fe2/ (Meier 2009 §6.4)
# over side pressures and RVE seeds, and draw docs/fe2.md's figures.
#
#   PACKD=build/packd sh bench/fe2/run_examples.sh OUT_DIR [SET ...]
#
# SETs (default: block_taylor block_rt biaxial_taylor):
#   block_taylor   block, Taylor, p = 0.1 0.2 0.3, seeds $SEEDS      (~10 s each)
#   block_rt       block, restricted Taylor, p = 0.2 0.1 0.3, seeds $RT_SEEDS (default 1;
#                  minutes each)
#   block_periodic block, periodic, p = 0.2 0.1 0.3, seeds $RT_SEEDS   (minutes each)
#   biaxial_taylor biaxial, Taylor, seeds $SEEDS
#   biaxial_rt     biaxial, restricted Taylor, seed 1                  (minutes)
#   slope          slope, Taylor, seed 1, 700-grain RVEs (SLOPE_GRAINS to reduce)
#   service        block, Taylor, p = 0.2 through `packd serve` + `packd submit`
# Every run writes OUT_DIR/<example>-<bc>[-p<p>]-s<seed>.{h5,json,err}; a run
# whose .h5 exists is skipped.  THREADS (default 2) threads per run; SEEDS
# (default "1 2 3"); WALL=S limits each run to S seconds (limits.wall_time_s:
# the run then ends failed with its converged steps).  Then /usr/bin/python3 bench/fe2/plot.py OUT_DIR OUT_DIR.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$(pwd)}
OUT=${1:?usage: run_examples.sh OUT_DIR [SET ...]}
shift
SETS=${*:-block_taylor block_rt biaxial_taylor}
THREADS=${THREADS:-2}
SEEDS=${SEEDS:-1 2 3}
mkdir -p "$OUT/jobs"
case $PACKD in /*) ;; *) PACKD=$(pwd)/$PACKD ;; esac

# job EXAMPLE BC P SEED: the job file (bench/fe2/make_examples.py with that p and seed)
job() {
    d="$OUT/jobs/p$3-s$4"
    [ -d "$d" ] || python3 "$SRC/bench/fe2/make_examples.py" --p "$3" --seed "$4" --out "$d" >/dev/null
    f=$(echo "$2" | tr _ -)
    case $1 in
    block) [ "$3" = 0.2 ] && echo "$d/block-$f.json" || echo "$d/block-$f-p$(echo "$3" | tr -d .).json" ;;
    *) echo "$d/$1-$f.json" ;;
    esac
}

# run EXAMPLE BC P SEED
run() {
    name="$1-$2$([ "$1" = block ] && echo "-p$3")-s$4"
    [ -s "$OUT/$name.h5" ] && return 0
    j=$(job "$@")
    if [ "$1" = slope ] && [ -n "${SLOPE_GRAINS:-}" ]; then
        python3 -c "
import json, sys; j = json.load(open('$j')); m = j['inputs']['micro']['rve']['pack']
m['count'] = $SLOPE_GRAINS; m['domain']['box']['size'] = [3.457 * ($SLOPE_GRAINS / 700) ** 0.5] * 2
json.dump(j, open('$OUT/jobs/slope-$SLOPE_GRAINS.json', 'w'))"
        j="$OUT/jobs/slope-$SLOPE_GRAINS.json"
    fi
    if [ -n "${WALL:-}" ]; then # a wall-time limit: the job fails with its converged steps
        python3 -c "
import json; j = json.load(open('$j')); j['inputs']['limits'] = {'wall_time_s': $WALL}
json.dump(j, open('$OUT/jobs/$name.json', 'w'))"
        j="$OUT/jobs/$name.json"
    fi
    t0=$(date +%s)
    "$PACKD" run "$j" -o "$OUT/$name.h5" --threads "$THREADS" --json >"$OUT/$name.json" 2>"$OUT/$name.err"
    rc=$?
    echo "bench=fe2 case=run name=$name exit=$rc seconds=$(($(date +%s) - t0))"
}

# service: block, Taylor, p = 0.2, seed 1 through the daemon (a temporary
# data directory, a free loopback port) — OUT_DIR/service/, beside the CLI's.
service() {
    mkdir -p "$OUT/service"
    name=service/block-taylor-p0.2-s1
    [ -s "$OUT/$name.h5" ] && return 0
    data=$(mktemp -d)
    "$PACKD" serve --bind 127.0.0.1 --port 0 --data "$data" --workers 1 --job-threads "$THREADS" \
        2>"$OUT/$name.serve.log" &
    pid=$!
    port=""
    for _ in $(seq 150); do
        port=$(grep '"msg":"listening"' "$OUT/$name.serve.log" | grep -o '"port":[0-9]*' | cut -d: -f2)
        [ -n "$port" ] && break
        sleep 0.2
    done
    t0=$(date +%s)
    "$PACKD" submit "$(job block taylor 0.2 1)" --server "http://127.0.0.1:$port" -q \
        -o "$OUT/$name.h5" >"$OUT/$name.json" 2>"$OUT/$name.err"
    rc=$?
    echo "bench=fe2 case=service port=$port exit=$rc seconds=$(($(date +%s) - t0))"
    kill "$pid"
    wait "$pid" 2>/dev/null
    rm -rf "$data"
}

for s in $SETS; do
    case $s in
    block_taylor) for seed in $SEEDS; do for p in 0.1 0.2 0.3; do run block taylor $p $seed; done; done ;;
    block_rt) for seed in ${RT_SEEDS:-1}; do for p in 0.2 0.1 0.3; do run block restricted_taylor $p $seed; done; done ;;
    block_periodic) for seed in ${RT_SEEDS:-1}; do for p in 0.2 0.1 0.3; do run block periodic $p $seed; done; done ;;
    biaxial_taylor) for seed in $SEEDS; do run biaxial taylor 0.2 $seed; done ;;
    biaxial_rt) run biaxial restricted_taylor 0.2 1 ;;
    slope) run slope taylor 0.2 1 ;;
    service) service ;;
    *) echo "run_examples.sh: unknown set $s" >&2 ;;
    esac
done
