#!/bin/sh
# bench/anchor_pg.sh — issue 37's mono case beside the anchor: PackingGeneration
# (`-fba` then `-ls 1e-2`, its README's protocol) and packd (bench/edmd_jam) on
# N equal spheres to reduced pressure 10^12, both certified by packd's rule
# (bench/anchor_certify).  The anchor is public code built outside the
# repository; point PACKD_PG_EXE at its PackingGeneration.exe (without it the
# script says so and exits 0).  CPU seconds = user + sys.  One line:
#   bench=anchor_pg n=N anchor_cpu_s=T anchor_phi=F anchor_certified=yes|no
#         packd_mode=M packd_cpu_s=T packd_phi=F packd_certified=yes|no ratio=packd/anchor
# PACKD_ANCHOR_N (default 10000), PACKD_ANCHOR_MODE (bench/edmd_jam mode,
# default rf1: one rate; `default` is the certified schedule),
# PACKD_BUILD (default build).
set -eu
exe=${PACKD_PG_EXE:-}
if [ -z "$exe" ] || [ ! -x "$exe" ]; then
    echo "bench=anchor_pg skipped (set PACKD_PG_EXE to a built PackingGeneration.exe)"
    exit 0
fi
n=${PACKD_ANCHOR_N:-10000}
mode=${PACKD_ANCHOR_MODE:-rf1}
build=${PACKD_BUILD:-build}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkdir "$dir/pg" "$dir/packd"
# the README's example box: nominal φ 0.6465 at diameter 1, Poisson start
L=$(awk -v n="$n" 'BEGIN { printf "%.15g", (n * 3.141592653589793 / 6 / 0.6465) ^ (1 / 3) }')
cat >"$dir/pg/generation.conf" <<EOF
Particles count: $n
Packing size: $L $L $L
Generation start: 1
Seed: 341
Steps to write: 1000
Boundaries mode: 1
Contraction rate: 1.328910e-002
EOF
cpu() { # cpu LOG CMD...: run CMD in the anchor's folder, user + sys seconds to LOG
    log=$1
    shift
    (cd "$dir/pg" && /usr/bin/time -f "%U %S" -o "$log" "$@" >/dev/null 2>&1)
}
cpu "$dir/fba.t" "$exe" -fba
rm -f "$dir/pg/packing.nfo"
sed -i 's/^Generation start: 1/Generation start: 0/' "$dir/pg/generation.conf"
cpu "$dir/ls.t" "$exe" -ls 1e-2
anchor_cpu=$(cat "$dir/fba.t" "$dir/ls.t" | awk '{ s += $1 + $2 } END { printf "%.2f", s }')
verdict() { # the certificate's verdict line of a PackingGeneration folder
    PACKD_ANCHOR_DIR=$1 "$build/bench/anchor_certify" | grep 'verdict'
}
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
a=$(verdict "$dir/pg")
a_phi=$(PACKD_ANCHOR_DIR="$dir/pg" "$build/bench/anchor_certify" | head -1 | field phi)
p=$(PACKD_BENCH_DUMP="$dir/packd" PACKD_BENCH_N=$n PACKD_BENCH_MODE=$mode "$build/bench/edmd_jam")
b=$(verdict "$dir/packd")
p_cpu=$(echo "$p" | field cpu_s)
echo "bench=anchor_pg n=$n anchor_cpu_s=$anchor_cpu anchor_phi=$a_phi" \
    "anchor_certified=$(echo "$a" | field certified) packd_mode=$mode packd_cpu_s=$p_cpu" \
    "packd_phi=$(echo "$p" | field phi) packd_certified=$(echo "$b" | field certified)" \
    "ratio=$(awk -v x="$p_cpu" -v y="$anchor_cpu" 'BEGIN { printf "%.3f", x / y }')"
