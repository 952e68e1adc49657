#!/bin/sh
# install-deps.sh [PURPOSE]... — install the Debian packages a purpose needs, only those
# missing.  Safe to run repeatedly (it only checks when nothing is missing).
#   run    build packd and run the daemon: `make`, `make run` (the default)
#   test   run + what `make test`'s tests drive (HDF5 tools, python, clang's fuzzer,
#          chromium and node for the dashboard, Slurm and munge, ParaView)
#   mpi    run + OpenMPI: fe2 runs over MPI ranks (mpirun, srun), after a make
#   bench  run + what bench/service.sh drives (wrk, sqlite3)
# `install-deps.sh --list PURPOSE` prints that purpose's packages, one per line
# (tests/integration/test_deps_list.sh holds the lists equal to what the build and the
# tests use).  As root it runs apt-get itself, as another user through sudo when sudo is
# installed; otherwise, or when sudo refuses, it prints the one command to run as root.
set -eu
# build + run: the compiler, the libraries packd links, a font for its pictures, and the
# curl and h5dump (hdf5-tools) the README's commands use
RUN_PKGS="build-essential pkg-config hdf5-tools libmicrohttpd-dev libcurl4-openssl-dev libssl-dev libjansson-dev libsqlite3-dev libhdf5-dev libsuitesparse-dev libopenblas0-serial libcairo2-dev fonts-dejavu-core curl"
# OpenMPI, which the build links when present (Makefile MPI=auto: `mpirun`/`srun` spread an
# fe2 run over ranks); 48 packages, 141 MB, so not in `run`: `install-deps.sh mpi`, then make
MPI_PKGS="openmpi-bin libopenmpi-dev"
# libomp-14-dev: clang's <omp.h> for the fuzz build; libopenblas0-pthread: the digest
# guard runs the solver against the threaded OpenBLAS too; clang-format: the format check;
# prometheus: promtool checks the /metrics exposition (test_metrics.sh)
# paraview, python3-paraview: pvbatch, ParaView's XDMF readers that test_xdmf opens every
# sidecar with (131 packages: 140 MB to download, 0.8 GB installed, 6.5 min on a busy 2-core machine)
PARAVIEW_PKGS="paraview python3-paraview"
TEST_PKGS="$MPI_PKGS $PARAVIEW_PKGS python3 python3-jsonschema python3-matplotlib python3-owslib procps clang libclang-rt-14-dev libomp-14-dev clang-format chromium nodejs libopenblas0-pthread slurm-wlm munge prometheus"
BENCH_PKGS="wrk sqlite3"
# The dashboard's browser test drives chromium with playwright-core from npm; a node
# from elsewhere (NodeSource) brings its own npm, which Debian's npm would conflict with.
command -v npm >/dev/null 2>&1 || TEST_PKGS="$TEST_PKGS npm"

pkgs_of() {
    case $1 in
    run) echo "$RUN_PKGS" ;;
    test) echo "$RUN_PKGS $TEST_PKGS" ;;
    mpi) echo "$RUN_PKGS $MPI_PKGS" ;;
    bench) echo "$RUN_PKGS $BENCH_PKGS" ;;
    *)
        echo "install-deps: unknown purpose '$1' (run, mpi, test or bench)" >&2
        exit 2
        ;;
    esac
}
if [ "${1:-}" = --list ]; then
    for p in $(pkgs_of "${2:-run}"); do echo "$p"; done
    exit 0
fi
[ $# -gt 0 ] || set -- run
PKGS=""
for purpose in "$@"; do PKGS="$PKGS $(pkgs_of "$purpose")"; done
# Older callers: PACKD_BENCH_DEPS=1 adds the bench tools.
[ "${PACKD_BENCH_DEPS:-0}" = 1 ] && PKGS="$PKGS $BENCH_PKGS"
if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: not a Debian system; install the equivalents of these by hand:" >&2
    echo " $PKGS" >&2
    exit 0
fi
missing=""
for p in $PKGS; do
    case " $missing " in *" $p "*) continue ;; esac
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "install-deps: missing Debian packages:$missing"
as_root() {
    echo "  su -c 'apt-get update && apt-get install -y --no-install-recommends$missing'" >&2
    echo "then run make again." >&2
    exit 1
}
if [ "$(id -u)" -eq 0 ]; then
    AS=""
elif command -v sudo >/dev/null 2>&1; then
    AS="sudo"
else
    echo "install-deps: not root and no sudo here; as root, run:" >&2
    as_root
fi
# env: sudo resets the environment
if ! $AS env DEBIAN_FRONTEND=noninteractive apt-get update -qq; then
    [ -n "$AS" ] && echo "install-deps: sudo could not run apt-get; as root, run:" >&2 && as_root
    exit 1
fi
# shellcheck disable=SC2086
$AS env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
