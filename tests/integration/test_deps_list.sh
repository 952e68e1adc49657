#!/bin/sh
# test_deps_list.sh — deploy/install-deps.sh's lists hold what the build and the tests
# really use, so that a package a development machine happens to have cannot hide a
# missing one on a fresh Debian:
#   - every header the sources include, as cc (the build) and clang (the fuzz build)
#     resolve it, comes from a listed package or one a listed package depends on: the
#     build's from `run`, the rest (clang's, OpenMPI's: the build links it when present) from `run` + `test`;
#   - every command the test scripts run comes from `run` + `test` or an Essential package.
# Needs dpkg and apt-cache (a Debian system).
. "${PACKD_SRC:-.}/tests/integration/check.inc"
SRC=${PACKD_SRC:-$(pwd)}
if ! command -v dpkg >/dev/null || ! command -v apt-cache >/dev/null; then
    skip deps_list "not a Debian system (no dpkg/apt-cache)"
    exit 0
fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
DEPS="$SRC/deploy/install-deps.sh"

# closure PURPOSE: its packages and every package they depend on, one per line
closure() {
    # shellcheck disable=SC2046
    apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
        --no-replaces --no-enhances $(sh "$DEPS" --list "$1") 2>/dev/null |
        grep -v '^ ' | sed 's/^<//; s/>$//; s/:amd64$//' | sort -u
    # what every Debian has: Essential and Priority required (debootstrap's minbase)
    dpkg-query -W -f='${Package} ${Essential} ${Priority}\n' | awk '$2 == "yes" || $3 == "required" { print $1 }'
}
closure run | sort -u >"$T/run"
closure test | sort -u >"$T/test"
check deps_lists_known sh -c "grep -qx libhdf5-dev '$T/run' && grep -qx python3-matplotlib '$T/test' && ! grep -qx python3-matplotlib '$T/run'"

# owner PATH...: "package path" for each file (dpkg's name without the architecture)
owner() {
    dpkg -S "$@" 2>/dev/null | grep -v '^diversion by' | sed 's/:[a-z0-9]*:/:/' | awk -F': ' '{ n = split($1, p, ", "); for (i = 1; i <= n; i++) print p[i], $2 }'
}

# --- headers: each <...> the tree includes, resolved by the compilers
grep -rhoE '^#[[:space:]]*include[[:space:]]*<[^>]+>' "$SRC/core" "$SRC/api" "$SRC/daemon" \
    "$SRC/tests/unit" "$SRC/tests/fuzz" "$SRC/bench" | sed 's/.*<\(.*\)>/\1/' | sort -u >"$T/headers"
PKGS="hdf5 jansson libmicrohttpd sqlite3 libcrypto cairo fontconfig libcurl"
# shellcheck disable=SC2086
CFLAGS="$(pkg-config --cflags $PKGS 2>/dev/null) -I/usr/include/suitesparse"
MPI_CFLAGS=$(pkg-config --cflags ompi-c 2>/dev/null)
# resolve CC HEADERS OUT [FLAGS]: the files the compiler reads for those headers
resolve() {
    sed 's/.*/#include <&>/' "$2" >"$T/h.c"
    # shellcheck disable=SC2086
    if $1 $CFLAGS ${4:-} -M -c "$T/h.c" -o "$T/h.d" 2>"$T/h.err"; then
        tr ' \\' '\n\n' <"$T/h.d" | grep '^/' | grep -v "^$T/" >"$3"
    else
        : >"$3"
        fail "headers_found_by_$1" "$(grep -m1 error "$T/h.err")"
    fi
}
# OpenMPI's <mpi.h> is an optional build dependency (Makefile: MPI=auto), in the run list
grep -vx 'mpi.h' "$T/headers" >"$T/headers.build"
grep -x 'mpi.h' "$T/headers" >"$T/headers.mpi"
# package_in LIST FILES PURPOSE: every file of FILES belongs to a package of LIST
package_in() {
    sort -u "$2" >"$2.u"
    [ -s "$2.u" ] || return 0
    # shellcheck disable=SC2046
    owner $(cat "$2.u") >"$2.own"
    bad=$(awk 'NR == FNR { ok[$1] = 1; next } !($1 in ok) { print $1 " (" $2 ")" }' "$1" "$2.own" | sort -u -k1,1)
    unowned=$(awk 'NR == FNR { seen[$2] = 1; next } !($0 in seen)' "$2.own" "$2.u" | head -3)
    if [ -n "$bad" ]; then
        fail "$3" "not in deploy/install-deps.sh's lists: $(echo "$bad" | tr '\n' ' ')"
    elif [ -n "$unowned" ]; then
        fail "$3" "from no Debian package: $(echo "$unowned" | tr '\n' ' ')"
    else
        pass "$3"
    fi
}
resolve cc "$T/headers.build" "$T/cc"
package_in "$T/run" "$T/cc" build_headers_in_run_list
if [ -s "$T/headers.mpi" ] && [ -n "$MPI_CFLAGS" ]; then
    resolve cc "$T/headers.mpi" "$T/mpi" "$MPI_CFLAGS"
    package_in "$T/test" "$T/mpi" mpi_headers_in_test_list
fi
if command -v clang >/dev/null; then
    resolve clang "$T/headers.build" "$T/clang"
    package_in "$T/test" "$T/clang" fuzz_build_headers_in_test_list
else
    skip fuzz_build_headers_in_test_list "clang is not installed"
fi

# --- commands: the words at a command's place in the test scripts that name a program
# on PATH; the scripts' own functions, and words of Python code or messages that land
# there (bc, ex, time), are not commands
cat "$SRC"/tests/integration/*.sh "$SRC"/tests/integration/*.inc "$SRC"/tests/tools/*.sh >"$T/scripts"
sed -n 's/^[[:space:]]*\([a-z_][a-z0-9_]*\)()[[:space:]]*{.*/\1/p' "$T/scripts" | sort -u >"$T/functions"
sed 's/#.*//' "$T/scripts" |
    grep -oE '(^|[|;&(]|\$\(|then |do |if |! |timeout [0-9]+ |exec |command -v )[[:space:]]*[a-z][a-z0-9_.+-]*([[:space:]]|$)' |
    grep -oE '[a-z][a-z0-9_.+-]*[[:space:]]*$' | tr -d ' \t' | sort -u |
    grep -vxF -f "$T/functions" | grep -vxE 'bc|ex|time' >"$T/words"
: >"$T/paths"
while read -r w; do
    p=$(command -v "$w" 2>/dev/null) || continue
    case $p in /*) ;; *) continue ;; esac # a shell builtin
    # /bin and /usr/bin are one directory (usrmerge): dpkg knows one of the names
    printf '%s %s\n' "$w" "$p" "$w" "$(readlink -f "$p")" "$w" "/usr/bin/$w" "$w" "/bin/$w" >>"$T/paths"
done <"$T/words"
# shellcheck disable=SC2046
owner $(awk '{ print $2 }' "$T/paths" | sort -u) >"$T/paths.own"
# each command's first owned name: "package path"
awk 'NR == FNR { pkg[$2] = $1; next } !($1 in done) && ($2 in pkg) { done[$1] = 1; print pkg[$2], $2 }
     !($1 in seen) { seen[$1] = $2 } END { for (w in seen) if (!(w in done)) print "(none)", seen[w] }' \
    "$T/paths.own" "$T/paths" >"$T/commands.own"
bad=$(awk 'NR == FNR { ok[$1] = 1; next } !($1 in ok) { print $1 " (" $2 ")" }' "$T/test" "$T/commands.own" | sort -u)
check test_commands_found test -s "$T/commands.own"
if [ -n "$bad" ]; then
    fail test_commands_in_test_list "not in deploy/install-deps.sh's lists: $(echo "$bad" | tr '\n' ' ')"
else
    pass test_commands_in_test_list
fi
