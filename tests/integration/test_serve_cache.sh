#!/bin/sh
# test_serve_cache.sh — result_cache_max_age_s: a CI pipeline that asks for
# the same RVE (same inputs and seed) again is answered at once from the
# owner's earlier successful job, with the same result (digest and bytes);
# Cache-Control: no-cache runs it afresh; another seed, another owner, or a
# cache age of 0 runs it; a dismissal of the first job leaves the answer's
# files; /metrics counts hits and misses (promtool reads it).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

WHO=alice
c() { curl -s --max-time $((20 * SLOW)) ${WHO:+-H @$T/$WHO.h} "$@"; }
token() { # NAME [--admin]: a token for NAME, its header file
    tok=$("$PACKD" token add "$@" --data "$T/ca" 2>/dev/null) || return 1
    printf 'Authorization: Bearer %s\n' "$tok" >"$T/$1.h"
}
token alice && token bob && token ops --admin || { fail token_add; exit 1; }
printf 'auth = on\nworkers = 1\nresult_cache_max_age_s = 3600\n' >"$T/ca.conf"
start_daemon ca --config "$T/ca.conf" || { fail serve_starts; exit 1; }

sync_submit() { # BODY [curl args]: the id of a job submitted with respond-sync, once it ended
    submit "$@" -H 'Prefer: respond-sync' >/dev/null
    sed -n 's/^link: <.*\/jobs\/\([^>]*\)>; rel="monitor".*/\1/Ip' "$T/submit.h" # 200: the job ended
}
reused() { # ID: its status document says it is another job's result
    c -o "$T/j.json" "$B/jobs/$1" && grep -q 'the result of job' "$T/j.json"
}
ran() { # ID: successful, and run by a worker of its own (it has a start time)
    c -o "$T/j.json" "$B/jobs/$1" && ! grep -q 'the result of job' "$T/j.json" &&
        grep -q '"started"' "$T/j.json" && grep -q '"status": "successful"' "$T/j.json"
}

A=$(sync_submit "$T/fast.json")
check first_runs wait_status "$A" successful 60
c -o "$T/a.h5" "$B/jobs/$A/results/result"

# the same request again: answered from A, at once, with A's bytes
t0=$(date +%s%N)
R=$(sync_submit "$T/fast.json")
ms=$((($(date +%s%N) - t0) / 1000000))
echo "# the repeated request answered in $ms ms"
check repeat_is_new_job test -n "$R" -a "$R" != "$A"
check repeat_successful test "$(status_of "$R")" = successful
from_a() { reused "$R" && grep -q "$A" "$T/j.json"; }
check repeat_names_source from_a
# logged once, as an answer: not as a job accepted for a worker
logged_as_answer() {
    grep '"msg":"job answered from an equal one"' "$LOG" | grep -q "\"job\":\"$R\"" &&
        ! grep '"msg":"job accepted"' "$LOG" | grep -q "\"job\":\"$R\""
}
check repeat_logged_as_answer logged_as_answer
c -o "$T/r.h5" "$B/jobs/$R/results/result"
check repeat_same_bytes cmp -s "$T/a.h5" "$T/r.h5"
check repeat_fast test "$ms" -lt $((2000 * SLOW))
c -o "$T/as.json" "$B/jobs/$A/results/summary"
c -o "$T/rs.json" "$B/jobs/$R/results/summary"
da=$(jget "$T/as.json" "d['result_digest']")
check repeat_same_digest test -n "$da" -a "$da" = "$(jget "$T/rs.json" "d['result_digest']")"

# the first job dismissed: the answer keeps its files
c -o /dev/null -X DELETE "$B/jobs/$A"
c -o "$T/r2.h5" "$B/jobs/$R/results/result"
check answer_outlives_source cmp -s "$T/a.h5" "$T/r2.h5"

# a fresh run when asked for, for another seed, for another owner
F=$(sync_submit "$T/fast.json" -H 'Cache-Control: no-cache')
check no_cache_runs ran "$F"
body_of "$SRC/examples/meier-quartz-2d.json" "i['seed'] = 7" >"$T/seed7.json"
S=$(sync_submit "$T/seed7.json")
check other_seed_runs ran "$S"
WHO=bob
Bj=$(sync_submit "$T/fast.json")
check other_owner_runs ran "$Bj"
WHO=alice

# /metrics: one hit; the no-cache request is not counted; seed 7, bob and A missed
WHO=ops c -o "$T/m.txt" "$B/metrics"
check metrics_hit grep -q '^packd_result_cache_requests_total{outcome="hit"} 1$' "$T/m.txt"
check metrics_miss grep -q '^packd_result_cache_requests_total{outcome="miss"} 3$' "$T/m.txt"
if command -v promtool >/dev/null 2>&1; then
    check promtool_reads_metrics sh -c "promtool check metrics <'$T/m.txt'"
else
    skip promtool_reads_metrics "promtool is not installed (apt-get install prometheus)"
fi

# a daemon without the setting runs every request
kill "$DPID"
wait_for 10 gone "$DPID"
printf 'auth = on\nworkers = 1\n' >"$T/off.conf"
start_daemon ca --config "$T/off.conf" || { fail serve_restarts; exit 1; }
O=$(sync_submit "$T/fast.json")
check cache_off_runs ran "$O"
