#!/bin/sh
# test_install.sh — docs/operations.md step by step in a temporary root:
# make install DESTDIR=… PREFIX=/usr/local, the installed unit's systemd-analyze
# security score, the installed binary serving on loopback (READY=1 on
# $NOTIFY_SOCKET), submit with the installed example, an online backup while
# it runs, a restore into a fresh data directory (integrity_check, the job and
# its result back); and deploy/install-deps.sh as root, with sudo, and with
# neither (stubbed apt-get, dpkg-query, id and sudo).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

ROOT="$T/root"
BUILD_DIR=${PACKD_BUILD:-$(dirname "$PACKD")}
# 1. install
make -s -C "$SRC" install BUILD="$BUILD_DIR" DESTDIR="$ROOT" PREFIX=/usr/local >"$T/install.log" 2>&1
check make_install_exit_0 test $? = 0
P="$ROOT/usr/local/bin/packd"
UNIT="$ROOT/usr/local/lib/systemd/system/packd.service"
DOC="$ROOT/usr/local/share/doc/packd"
check installed_files sh -c "[ -x '$P' ] && [ -f '$UNIT' ] && [ -f '$ROOT/etc/packd/packd.conf' ] && [ -f '$DOC/operations.md' ] && [ -f '$DOC/examples/meier-quartz-2d.json' ]"
check unit_paths_rewritten grep -q '^ExecStart=/usr/local/bin/packd serve --config /etc/packd/packd.conf' "$UNIT"
echo "# edited" >>"$ROOT/etc/packd/packd.conf"
make -s -C "$SRC" install BUILD="$BUILD_DIR" DESTDIR="$ROOT" PREFIX=/usr/local >/dev/null 2>&1
check install_keeps_config grep -q '^# edited' "$ROOT/etc/packd/packd.conf"

# 2. the unit's sandbox
if command -v systemd-analyze >/dev/null 2>&1; then
    score=$(systemd-analyze security --offline=yes "$UNIT" 2>/dev/null | sed -n 's/.*Overall exposure level for packd.service: \([0-9.]*\) .*/\1/p')
    echo "systemd-analyze security: $score"
    check unit_exposure_at_most_3 python3 -c "import sys; sys.exit(0 if 0 < float('$score' or 99) <= 3.0 else 1)"
else
    echo "(systemd-analyze not installed: the unit's score is not measured)"
fi

# 3. serve with the installed binary; readiness on NOTIFY_SOCKET
python3 -c "
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM); s.bind(sys.argv[1]); s.settimeout(30)
open(sys.argv[2], 'w').write(s.recv(256).decode())" "$T/notify.sock" "$T/notify.txt" &
i=0
while [ ! -S "$T/notify.sock" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
PACKD=$P
NOTIFY_SOCKET="$T/notify.sock" start_daemon state --config "$ROOT/etc/packd/packd.conf" --workers 1 ||
    { fail installed_serves; exit 1; }
i=0
while [ ! -s "$T/notify.txt" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
check ready_notified grep -qx 'READY=1' "$T/notify.txt"
export PACKD_SERVER=$B
"$P" submit "$DOC/examples/meier-quartz-2d.json" -q -o "$T/one.h5" >"$T/submit.out"
check installed_submit_exit_0 test $? = 0
ID=$(member "$T/submit.out" jobID)

# 4. back up while it serves
"$P" backup "$T/backup.db" --data "$T/state" >"$T/backup.json"
check backup_exit_0 test $? = 0
check backup_reports_ok sh -c "grep -q '\"integrity\": \"ok\"' '$T/backup.json' && grep -q '\"jobs\": 1' '$T/backup.json'"
check backup_integrity_check test "$(python3 -c "import sqlite3,sys; print(sqlite3.connect(sys.argv[1]).execute('PRAGMA integrity_check').fetchone()[0])" "$T/backup.db")" = ok
check backup_is_one_file test ! -e "$T/backup.db-wal" -a ! -e "$T/backup.db.tmp"
# and while the daemon writes (three submissions at once)
pids=""
for k in 1 2 3; do
    c -o /dev/null -H 'Content-Type: application/json' --data-binary @"$T/fast.json" "$B/processes/pack/execution" &
    pids="$pids $!"
done
"$P" backup "$T/busy.db" --data "$T/state" >"$T/busy.json"
check backup_while_writing sh -c "grep -q '\"integrity\": \"ok\"' '$T/busy.json'"
for p in $pids; do wait "$p"; done
tar -C "$T/state" -czf "$T/files.tgz" jobs
"$P" backup "$T/nowhere.db" --data "$T/missing" 2>/dev/null
check backup_missing_database_fails test $? = 2

# 5. restore into a fresh data directory and serve it
kill -TERM "$DPID"
mkdir -p "$T/restored"
cp "$T/backup.db" "$T/restored/queue.db" && rm -f "$T/restored/queue.db-wal" "$T/restored/queue.db-shm"
tar -C "$T/restored" -xzf "$T/files.tgz"
start_daemon restored --workers 1 || { fail restored_serves; exit 1; }
PACKD_SERVER=$B "$P" jobs >"$T/jobs.txt"
check restored_job_listed sh -c "grep '$ID' '$T/jobs.txt' | grep -q successful"
PACKD_SERVER=$B "$P" fetch "$ID" -o "$T/two.h5" >/dev/null
check restored_fetch_exit_0 test $? = 0
check restored_result_same_bytes cmp -s "$T/one.h5" "$T/two.h5"

# 6. install-deps.sh: root, sudo, sudo that refuses, neither (stubs; nothing is installed)
stub() { # DIR NAME BODY
    printf '#!/bin/sh\n%s\n' "$3" >"$1/$2"
    chmod +x "$1/$2"
}
for case in root sudo denied neither; do
    d="$T/stub-$case"
    mkdir -p "$d"
    for tool in grep env; do ln -s "$(command -v $tool)" "$d/$tool"; done
    stub "$d" dpkg-query 'if [ "$3" = curl ]; then echo "unknown ok not-installed"; else echo "install ok installed"; fi'
    stub "$d" apt-get "echo \"apt-get \$*\" >>'$T/apt-$case.log'"
    case $case in root) uid=0 ;; *) uid=1000 ;; esac
    stub "$d" id "echo $uid"
    [ $case = sudo ] && stub "$d" sudo "echo \"sudo \$1\" >>'$T/apt-$case.log'; exec \"\$@\""
    [ $case = denied ] && stub "$d" sudo "echo 'alice is not in the sudoers file.' >&2; exit 1"
    PATH="$d" /bin/sh "$SRC/deploy/install-deps.sh" >"$T/deps-$case.out" 2>&1
    echo $? >"$T/deps-$case.rc"
done
check deps_as_root sh -c "[ \$(cat '$T/deps-root.rc') = 0 ] && grep -q 'apt-get install .* curl' '$T/apt-root.log' && ! grep -q sudo '$T/apt-root.log'"
check deps_with_sudo sh -c "[ \$(cat '$T/deps-sudo.rc') = 0 ] && grep -q '^sudo env' '$T/apt-sudo.log' && grep -q 'apt-get install .* curl' '$T/apt-sudo.log'"
check deps_sudo_refused_says_what_to_run sh -c "[ \$(cat '$T/deps-denied.rc') != 0 ] && grep -q 'sudoers' '$T/deps-denied.out' && grep -q \"su -c 'apt-get update && apt-get install -y --no-install-recommends curl'\" '$T/deps-denied.out' && [ ! -e '$T/apt-denied.log' ]"
check deps_neither_says_what_to_run sh -c "[ \$(cat '$T/deps-neither.rc') != 0 ] && grep -q \"su -c 'apt-get update && apt-get install -y --no-install-recommends curl'\" '$T/deps-neither.out' && ! grep -q 'not found' '$T/deps-neither.out' && [ ! -e '$T/apt-neither.log' ]"
