#!/bin/sh
# test_checkpoint_cli.sh — `packd run --checkpoint` for a multi-step
# homogenization: killed (-9) after a saved load step, the rerun resumes from
# that step and ends with the same stresses, bit for bit, as an uninterrupted
# run (the committed state is restored exactly: centres, contacts, rotations,
# friction history); a checkpoint of another job is not used.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-$(pwd)}
. "$SRC/tests/integration/check.inc"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1
cp "$SRC/examples/homogenize/rve-rsa-2d.json" .
"$PACKD" run rve-rsa-2d.json -o rve-2d.h5 >/dev/null 2>&1 || { fail checkpoint_rve; exit 1; }
# the friction example (Meier 2009 §7.4) with a long cyclic path: ~300 steps
python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
j['inputs']['load']['steps'] = 300
print(json.dumps(j))" "$SRC/examples/homogenize/homogenize-friction-taylor-2d.json" >cyc.json
"$PACKD" run cyc.json -o ref.h5 >ref.json 2>ref.err || fail checkpoint_reference_run "$(cat ref.err)"

"$PACKD" run cyc.json -o res.h5 --checkpoint ck.h5 --checkpoint-interval 0.05 >/dev/null 2>&1 &
pid=$!
i=0
while [ ! -f ck.h5 ] && kill -0 $pid 2>/dev/null && [ $i -lt 3000 ]; do sleep 0.01; i=$((i + 1)); done
# a later step saved: each checkpoint is written aside and renamed, a new inode
first=$(stat -c %i ck.h5 2>/dev/null)
while [ "$(stat -c %i ck.h5 2>/dev/null)" = "$first" ] && kill -0 $pid 2>/dev/null && [ $i -lt 3000 ]; do
    sleep 0.01
    i=$((i + 1))
done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
check checkpoint_homog_saved test -f ck.h5
cp ck.h5 ck-copy.h5
"$PACKD" run cyc.json -o res.h5 --checkpoint ck.h5 >res.json 2>res.err || fail checkpoint_homog_resumed_run "$(cat res.err)"
python3 -c "
import json
a, b = json.load(open('ref.json')), json.load(open('res.json'))
print('homogenize: resumed from step %s of %s' % (b.get('resumed_from_step'), b['steps']))
assert b.get('resumed_from_step', 0) > 0, b.get('resumed_from_step')
assert a['steps'] == b['steps'] and a['P'] == b['P'] and a['sigma'] == b['sigma'], (a['P'], b['P'])
assert a['dr_iterations_total'] == b['dr_iterations_total']" && pass checkpoint_homog_resume_same_result || fail checkpoint_homog_resume_same_result
check checkpoint_homog_removed_at_end test ! -e ck.h5
"$PACKD" inspect res.h5 >res.inspect 2>&1
check checkpoint_homog_said_in_file grep -q '"homogenize/resumed_from_step"' res.inspect

# another job (other E_n): the checkpoint is refused and the job starts anew
python3 -c "
import json
j = json.load(open('cyc.json')); j['inputs']['contact']['E_n'] = 60
print(json.dumps(j))" >other.json
cp ck-copy.h5 ck.h5
"$PACKD" run other.json -o other.h5 --checkpoint ck.h5 >other.out 2>&1
"$PACKD" inspect other.h5 >other.inspect 2>&1
check checkpoint_other_job_refused sh -c "! grep -q resumed_from_step other.out && grep -q 'belongs to another job' other.inspect"
