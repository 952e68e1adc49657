#!/bin/sh
# test_serve_readers.sh — reads never wait on the writer (docs/service.md,
# "Database"): while another connection holds the queue database's write lock
# and a worker reports progress (the daemon's writer then sits in its 5 s busy
# wait, as it would behind a slow fsync), /healthz, a job's status and a token
# check that records the token's use answer at once from read-only
# connections.  On a read path that shares the writer each waits out the
# busy timeout.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

WHO=""
c() { curl -s --max-time $((20 * SLOW)) ${WHO:+-H @$T/$WHO.h} "$@"; }
token() { # NAME: make an admin token, write NAME's header file
    tok=$("$PACKD" token add "$1" --data "$T/rd" --admin 2>/dev/null) || return 1
    printf 'Authorization: Bearer %s\n' "$tok" >"$T/$1.h"
}
# seconds NAME URL: the request's total time as NAME (curl's time_total), and
# its status in $T/code
seconds() {
    WHO=$1
    c -o /dev/null -w '%{http_code} %{time_total}\n' "$2" >"$T/timed"
    WHO=""
    cut -d' ' -f1 "$T/timed" >"$T/code"
    cut -d' ' -f2 "$T/timed"
}
below() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a + 0 < b + 0) }'; }
answered_at_once() { # SECONDS: a 200 well under the bar (else says what came)
    [ "$(cat "$T/code")" = 200 ] && below "$1" $BAR && return 0
    echo "# answered $(cat "$T/code") after $1 s; the daemon's last lines:"
    tail -5 "$LOG" | sed 's/^/# /'
    return 1
}
# the bar: well under the 5 s busy timeout a waiting read would sit out
BAR=2.5

token alice && token fresh || { fail token_add; exit 1; }
printf 'auth = on\nworkers = 1\n' >"$T/rd.conf"
start_daemon rd --config "$T/rd.conf" || { fail serve_starts; exit 1; }
WHO=alice
edmd_slow_body 120 >"$T/slow.json"
ID=$(submit "$T/slow.json")
check job_running wait_status "$ID" running 60
WHO=""

# hold the write lock from another connection until $T/release appears
python3 - "$T/rd/queue.db" "$T/locked" "$T/release" <<'PY' &
import os, sqlite3, sys, time
db = sqlite3.connect(sys.argv[1], isolation_level=None, timeout=30)
db.execute("BEGIN IMMEDIATE")
open(sys.argv[2], "w").close()
end = time.time() + 120
while not os.path.exists(sys.argv[3]) and time.time() < end:
    time.sleep(0.05)
db.execute("ROLLBACK")
PY
HOLDER=$!
wait_for 30 test -e "$T/locked" || fail lock_taken

# the worker's next progress line (every 0.5 s) puts the writer behind the lock
slowest=0
for _ in 1 2 3 4 5 6 7 8; do
    t=$(seconds "" "$B/healthz")
    below "$t" "$slowest" || slowest=$t
    sleep 0.25 # samples across the writer's busy wait
done
echo "# slowest /healthz while the write lock is held: $slowest s"
check healthz_not_waiting below "$slowest" $BAR
t=$(seconds alice "$B/jobs/$ID")
check status_not_waiting answered_at_once "$t"
# a token never used before: its check records last_used, a write
t=$(seconds fresh "$B/jobs")
check fresh_token_not_waiting answered_at_once "$t"
touch "$T/release"
wait "$HOLDER"

# the writer goes on once the lock is gone
WHO=alice
c -o /dev/null -X DELETE "$B/jobs/$ID"
check writer_works_after test -n "$(submit "$T/fast.json")"
