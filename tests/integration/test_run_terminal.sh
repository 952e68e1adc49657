#!/bin/sh
# test_run_terminal.sh — `packd run` as a person sees it: under a
# pseudo-terminal a live progress line on stderr (redrawn in place with \r and
# erase-to-end-of-line) and a short human summary on stdout; with --json or a
# stdout that is not a terminal, the summary as JSON without the time series
# (they are in the result file); --progress keeps its JSON lines.
set -u
PACKD=${PACKD:-build/packd}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "${PACKD_SRC:-.}/tests/integration/check.inc"

# an EDMD job of well under a second that reports several times at 10/s
sed 's/"count": 1000/"count": 2500/' examples/edmd-quartz-2d.json >"$T/job.json"

# run ARGS under terminals: stdout and stderr each a pty of its own (so they
# are told apart), their bytes saved to $T/$1.out and $T/$1.err
cat >"$T/terminals.py" <<'EOF2'
import os, pty, select, subprocess, sys
name, argv = sys.argv[1], sys.argv[2:]
mo, so = pty.openpty()
me, se = pty.openpty()
env = dict(os.environ, LANG="C.UTF-8", TERM="xterm")
env.pop("LC_ALL", None); env.pop("LC_CTYPE", None)
p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=so, stderr=se, env=env)
os.close(so); os.close(se)
got = {mo: b"", me: b""}
open_fds = [mo, me]
while open_fds:
    r, _, _ = select.select(open_fds, [], [], 60)
    if not r:
        break
    for fd in r:
        try:
            b = os.read(fd, 65536)
        except OSError:  # EIO: the slave side is closed
            b = b""
        if b:
            got[fd] += b
        else:
            open_fds.remove(fd)
rc = p.wait(timeout=60)
open(name + ".out", "wb").write(got[mo])
open(name + ".err", "wb").write(got[me])
sys.exit(rc)
EOF2

# 1. a terminal: the progress line, redrawn in place, then the human summary
if python3 "$T/terminals.py" "$T/tty" "$PACKD" run "$T/job.json" -o "$T/tty.h5"; then
    pass run_tty_exit_0
else
    fail run_tty_exit_0 "$(cat "$T/tty.err")"
fi
check run_tty_progress_line python3 -c "
e = open('$T/tty.err', 'rb').read().decode()
frames = [f for f in e.split('\r') if f.strip('\x1b[K\r\n ')]
assert len(frames) >= 2, repr(e)                 # drawn, then redrawn in place
assert all(f.startswith('edmd ') and '%' in f and 'φ 0.' in f and ' s' in f for f in frames), frames
assert all(f.endswith('\x1b[K') for f in frames), frames   # erased to the end of the line
assert '\n' not in e and e.endswith('\r\x1b[K'), repr(e[-40:])   # one line, erased at the end
"
check run_tty_human_summary python3 -c "
o = open('$T/tty.out', 'rb').read().decode().replace('\r\n', '\n')
assert o.startswith('pack (edmd): successful, complete (target)\n'), o  # the stop named
for s in ('grains    2500 placed of 2500 requested', 'φ         0.8000 resolved (target 0.8000)',
          'time ', 'output    $T/tty.h5'):
    assert s in o, (s, o)
assert '{' not in o and len(o.splitlines()) < 12, o
"

# 2. stdout not a terminal: the JSON summary, valid, without the history arrays
"$PACKD" run "$T/job.json" -o "$T/pipe.h5" >"$T/pipe.json" 2>"$T/pipe.err"
check run_pipe_json_without_series python3 -c "
import json
d = json.load(open('$T/pipe.json'))
def walk(o):
    if isinstance(o, dict):
        assert 'history' not in o, list(o)
        for v in o.values(): walk(v)
walk(d)
assert d['complete'] and d['count_placed'] == 2500
assert 'output' not in d and 'xdmf' not in d, list(d)  # the caller named its files
assert len(d['result_digest']) == 64 and d['edmd']['events'] > 0
"
check run_pipe_stderr_quiet test ! -s "$T/pipe.err"
# the series are in the result file
check run_series_in_file sh -c "'$PACKD' inspect --full '$T/pipe.h5' | python3 -c \"
import json, sys; o = json.load(sys.stdin)['observables']; assert len(o['edmd/history/phi']) > 10\""

# 3. --json on a terminal: the same JSON summary (the live line stays on stderr)
python3 "$T/terminals.py" "$T/json" "$PACKD" run "$T/job.json" -o "$T/json.h5" --json
check run_tty_json_summary python3 -c "
import json
d = json.loads(open('$T/json.out', 'rb').read().decode())
p = json.load(open('$T/pipe.json'))
assert sorted(d) == sorted(p) and 'history' not in d['edmd'], sorted(d)
assert '\r' in open('$T/json.err', 'rb').read().decode()
"

# 4. --progress: JSON lines on stderr as before, no live line among them
python3 "$T/terminals.py" "$T/prog" "$PACKD" run "$T/job.json" -o "$T/prog.h5" --progress
check run_progress_json_lines python3 -c "
import json
lines = open('$T/prog.err', 'rb').read().decode().replace('\r\n', '\n').splitlines()
assert lines and all(json.loads(l)['stage'] for l in lines), lines[:3]
"
