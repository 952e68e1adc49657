#!/bin/sh
# test_client.sh — packd's command-line client against a real daemon on
# loopback: submit --wait -o fetches and verifies a result in one line, an
# invalid job exits 1 with its pointers, jobs lists, fetch re-downloads,
# cancel dismisses a running job; against a stand-in service
# (fake_service.py): a tampered or cut download is refused (exit 2), a failed
# job exits 3 with its partial file at OUT.partial (OUT itself not written),
# the token is sent as a bearer token.
# Every subcommand answers --help.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# the stand-in service starts while the rest runs
python3 "$SRC/tests/integration/fake_service.py" "$T/fake.port" "$T/fake.log" &
DAEMONS="$DAEMONS $!"

for cmd in run validate inspect serve picture token submit jobs cancel fetch backup; do
    check "help_$cmd" sh -c "'$PACKD' $cmd --help >'$T/help.txt' 2>&1 && grep -q 'usage: packd $cmd' '$T/help.txt'"
done

start_daemon d1 --workers 2 || { fail serve_starts; exit 1; }
# a long job to cancel later, running beside the rest
slow_body 30 | python3 -c "import json,sys; d=json.load(sys.stdin); d['process']='pack'; print(json.dumps(d))" >"$T/slow.json"
"$PACKD" submit "$T/slow.json" --server "$B" >"$T/slow.out"
SID=$(member "$T/slow.out" jobID)

# 1. one line: submit, follow, download, verify
"$PACKD" submit "$SRC/examples/meier-quartz-2d.json" --server "$B" --wait -o "$T/out.h5" \
    >"$T/submit.out" 2>"$T/submit.err"
check submit_wait_exit_0 test $? = 0
ID=$(member "$T/submit.out" jobID)
c "$B/jobs/$ID/results" >"$T/res.json"
server_sha=$(jget "$T/res.json" 'd["result"]["sha256"]')
client_sha=$(member "$T/submit.out" sha256)
check submit_result_matches_server_sha sh -c "[ -n '$server_sha' ] && [ \"\$(sha256sum '$T/out.h5' | cut -d' ' -f1)\" = '$server_sha' ] && [ '$client_sha' = '$server_sha' ]"
check submit_result_opens sh -c "'$PACKD' inspect '$T/out.h5' | grep -q '\"count\": 1000' || h5dump -H '$T/out.h5' >/dev/null"
check submit_progress_line_on_stderr grep -q "job ${ID%%-*} successful" "$T/submit.err"
check no_part_file_left test ! -e "$T/out.h5.part"

# 1b. a job that fails (its wall time): exit 3; -o's file is not written, the
# partial result is at OUT.partial and the message says so
slow_body 1 | python3 -c "import json,sys; d=json.load(sys.stdin); d['process']='pack'; print(json.dumps(d))" >"$T/fails.json"
"$PACKD" submit "$T/fails.json" --server "$B" -q -o "$T/fails.h5" >"$T/fails.out" 2>"$T/fails.err"
check submit_failed_exit_3 test $? = 3
check submit_failed_output_not_written test ! -e "$T/fails.h5"
check submit_failed_partial_at_dot_partial sh -c "h5dump -d /observables/verdict/status '$T/fails.h5.partial' | grep -q failed"
check submit_failed_message_names_partial grep -q "partial result of the failed job in $T/fails.h5.partial" "$T/fails.err"

# 2. an invalid job: exit 1, each error's pointer and message on stderr
printf '{"process": "pack", "inputs": {"dim": 5}}\n' >"$T/bad.json"
"$PACKD" submit "$T/bad.json" --server "$B" --wait -o "$T/bad.h5" >/dev/null 2>"$T/bad.err"
check invalid_job_exit_1 test $? = 1
check invalid_job_pointer_printed grep -q '/inputs/dim: must be one of 2, 3' "$T/bad.err"

# 3. jobs lists it; fetch re-downloads and verifies
PACKD_SERVER=$B "$PACKD" jobs >"$T/jobs.txt"
check jobs_lists_the_job sh -c "grep '$ID' '$T/jobs.txt' | grep -q successful"
"$PACKD" fetch "$ID" -o "$T/again.h5" --server "$B" >"$T/fetch.out"
check fetch_exit_0 test $? = 0
check fetch_same_bytes cmp -s "$T/out.h5" "$T/again.h5"

# 4. cancel a running job
wait_status "$SID" running 20
"$PACKD" cancel "$SID" --server "$B" >/dev/null
check cancel_exit_0 test $? = 0
check cancel_dismisses wait_status "$SID" dismissed 10
"$PACKD" fetch "$SID" -o "$T/none.h5" --server "$B" 2>/dev/null
check fetch_dismissed_exit_3 test $? = 3

# 5. no service: a transport error, exit 2
"$PACKD" jobs --server http://127.0.0.1:1 2>"$T/conn.err"
check no_service_exit_2 test $? = 2

# 6. a service whose bytes do not match their digest
i=0
while [ ! -s "$T/fake.port" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
F="http://127.0.0.1:$(cat "$T/fake.port")"
PACKD_TOKEN=secret-t "$PACKD" fetch good -o "$T/good.bin" --server "$F" >/dev/null 2>&1
check fake_good_exit_0 test $? = 0
check token_sent_as_bearer grep -q '^/jobs/good/results/result Bearer secret-t$' "$T/fake.log"
"$PACKD" fetch abs -o "$T/abs.bin" --server "$F" --token t2 >/dev/null 2>&1
check absolute_link_fetched_from_server sh -c "[ -s '$T/abs.bin' ] && grep -q '^/jobs/abs/results/result Bearer t2$' '$T/fake.log'"
for bad in tampered short badheader digest; do
    "$PACKD" fetch $bad -o "$T/$bad.bin" --server "$F" --token x >/dev/null 2>"$T/$bad.err"
    check "${bad}_download_exit_2" test $? = 2
    check "${bad}_download_removed" test ! -e "$T/$bad.bin" -a ! -e "$T/$bad.bin.part"
done
check tampered_says_mismatch grep -q 'SHA-256 mismatch' "$T/tampered.err"
check digest_says_stated grep -q 'result_digest .*the server states 0000' "$T/digest.err"
"$PACKD" fetch failed -o "$T/partial.bin" --server "$F" >/dev/null 2>"$T/failed.err"
check failed_job_exit_3 test $? = 3
check failed_job_reason_printed grep -q 'ran out of wall time' "$T/failed.err"
check failed_job_partial_kept test -s "$T/partial.bin.partial"
# -o names the file of a successful job only: a pipeline that tests its existence stops here
check failed_job_output_not_written test ! -e "$T/partial.bin"
check failed_job_names_partial_file grep -q "partial result of the failed job in $T/partial.bin.partial" "$T/failed.err"

# 7. a service with auth on: the token from $PACKD_TOKEN opens it, none gets 401 (exit 1)
tok=$("$PACKD" token add alice --data "$T/authd" 2>/dev/null)
printf 'auth = on\nworkers = 1\n' >"$T/auth.conf"
start_daemon authd --config "$T/auth.conf" || { fail auth_serve_starts; exit 1; }
PACKD_TOKEN=$tok "$PACKD" submit "$SRC/examples/meier-quartz-2d.json" --server "$B" -q -o "$T/auth.h5" >/dev/null 2>"$T/auth.err"
check auth_submit_with_token_exit_0 test $? = 0
"$PACKD" jobs --server "$B" >/dev/null 2>"$T/noauth.err"
check auth_without_token_exit_1 test $? = 1
check auth_without_token_says_401 grep -q '401' "$T/noauth.err"
