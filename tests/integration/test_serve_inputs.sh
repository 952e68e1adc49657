#!/bin/sh
# test_serve_inputs.sh — files named by path in a request never reach
# outside the data directory (issue 20).  Without input_dir a server path
# (rve.file, domain.mesh.file) is refused with 422 naming the field; with
# input_dir, a file inside is taken and runs, while "..", a symlink out, an
# absolute path elsewhere, a FIFO and /dev/zero are refused at once — the
# HTTP threads never open them, so /healthz answers right after 30 of them.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

# post PROCESS BODYFILE OUT: prints the status code
post() { c -o "$3" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$2" "$B/processes/$1/execution"; }
# has_error OUT POINTER RULE (the daemon's indented JSON: pointer, then rule)
has_error() { grep -A1 "\"pointer\": \"$2\"" "$1" | grep -q "\"rule\": \"$3\""; }

MESH="$SRC/tests/data/meshes/cylinder41.msh"
IN="$T/in"
OUT="$T/outside"
CASES="dotdot:../outside/secret.msh symlink_out:escape.msh absolute_out:$OUT/secret.msh
dev_zero:/dev/zero symlink_dev_zero:zero.msh fifo:fifo.msh directory:sub missing:nope.msh"
EXTRA="fifo_abs:$IN/fifo.msh"
# every body at once (python starts slowly on a loaded machine)
python3 -c "
import json,sys
src, mesh, t = sys.argv[1:4]
def inputs(f): return json.load(open(src + '/examples/' + f))['inputs']
def put(name, i): json.dump({'inputs': i}, open(t + '/' + name + '.json', 'w'))
h = inputs('homogenize/homogenize-periodic-2d.json'); h['rve'] = {'file': mesh}; put('rve_path', h)
for name, path in [('mesh_path', mesh), ('inside', 'sub/cyl.msh')] + [c.split(':', 1) for c in sys.argv[4:]]:
    i = inputs('tetfill-cylinder.json'); i['domain']['mesh'] = {'file': path}; put(name, i)
i = inputs('tetfill-cylinder.json'); i['domain']['mesh'] = {'href': 'HREF'}; put('upload', i)
" "$SRC" "$MESH" "$T" $CASES $EXTRA

# burst N BODY_A BODY_B NAME: N requests at once, alternating the bodies; all
# must be refused (422) and /healthz must answer within 1 s afterwards (no
# HTTP thread left reading a FIFO or /dev/zero)
burst() {
    i=0
    pids=""
    while [ $i -lt "$1" ]; do
        f=$2
        [ $((i % 2)) -eq 0 ] && f=$3
        curl -s --max-time 10 -o /dev/null -w '%{http_code}\n' -H 'Content-Type: application/json' \
            --data-binary "@$f" "$B/processes/pack/execution" >"$T/burst.$4.$i" &
        pids="$pids $!"
        i=$((i + 1))
    done
    for p in $pids; do wait "$p"; done
    check "burst_${4}_all_refused" sh -c "test \$(cat '$T'/burst.$4.* | grep -c '^422$') -eq $1"
    check "healthz_${4}" sh -c "test \"\$(curl -s --max-time 1 -o /dev/null -w '%{http_code}' '$B/healthz')\" = 200"
}

mkdir -p "$IN/sub" "$OUT"
mkfifo "$IN/fifo.msh"
start_daemon closed --workers 0 || { fail serve_starts; exit 1; }
code=$(post homogenize "$T/rve_path.json" "$T/o1.json")
check rve_server_path_422 test "$code" = 422
check rve_server_path_names_field has_error "$T/o1.json" /inputs/rve/file serverPath
code=$(post pack "$T/mesh_path.json" "$T/o2.json")
check mesh_server_path_422 test "$code" = 422
check mesh_server_path_names_field has_error "$T/o2.json" /inputs/domain/mesh/file serverPath
# the issue's case: /dev/zero and a FIFO as mesh files, without an input directory
burst 30 "$T/dev_zero.json" "$T/fifo_abs.json" no_input_dir

cp "$MESH" "$IN/sub/cyl.msh"
cp "$MESH" "$OUT/secret.msh"
ln -s "$OUT/secret.msh" "$IN/escape.msh"
ln -s /dev/zero "$IN/zero.msh"
start_daemon open --workers 1 --input-dir "$IN" || { fail serve_starts_input_dir; exit 1; }

code=$(post pack "$T/inside.json" "$T/o3.json")
check inside_accepted test "$code" = 201
check inside_runs wait_status "$(member "$T/o3.json" jobID)" successful 120

# an upload that is no mesh: accepted (nothing is read in the request), the worker fails it with the reason
printf 'no mesh here\n' >"$T/junk"
c -o "$T/up.json" -H 'Content-Type: application/octet-stream' --data-binary "@$T/junk" "$B/files"
sed "s|HREF|$(member "$T/up.json" href)|" "$T/upload.json" >"$T/upload2.json"
code=$(post pack "$T/upload2.json" "$T/o4.json")
check junk_upload_accepted test "$code" = 201
J=$(member "$T/o4.json" jobID)
check junk_upload_fails wait_status "$J" failed 60
check junk_upload_reason grep -q 'neither a Gmsh MSH file' "$T/st.json"

for case in $CASES; do
    nm=${case%%:*}
    code=$(post pack "$T/$nm.json" "$T/$nm.out")
    check "${nm}_refused" test "$code" = 422
    check "${nm}_names_field" has_error "$T/$nm.out" /inputs/domain/mesh/file inputDir
done
check refusal_hides_target sh -c "! grep -q secret '$T/symlink_out.out'"

# 30 hostile requests at once (a FIFO and /dev/zero), then /healthz within 1 s
burst 30 "$T/fifo.json" "$T/symlink_dev_zero.json" after_input_dir

# a file swapped for a symlink out of input_dir after the 201 (and a
# directory swapped likewise) is not read: the worker opens beneath input_dir
cp "$MESH" "$IN/swap.msh"
mkdir -p "$IN/swapdir" && cp "$MESH" "$IN/swapdir/cyl.msh"
sed 's|sub/cyl.msh|swap.msh|' "$T/inside.json" >"$T/swap.json"
sed 's|sub/cyl.msh|swapdir/cyl.msh|' "$T/inside.json" >"$T/swapdir.json"
chmod 600 "$OUT/secret.msh"
printf 'workers = 0\ninput_dir = %s\n' "$IN" >"$T/swap.conf"
start_daemon swap --config "$T/swap.conf" || { fail serve_starts_swap; exit 1; }
code=$(post pack "$T/swap.json" "$T/o5.json")
check swap_accepted test "$code" = 201
S1=$(member "$T/o5.json" jobID)
code=$(post pack "$T/swapdir.json" "$T/o6.json")
check swapdir_accepted test "$code" = 201
S2=$(member "$T/o6.json" jobID)
code=$(post pack "$T/inside.json" "$T/o7.json")
S3=$(member "$T/o7.json" jobID)
rm "$IN/swap.msh" && ln -s "$OUT/secret.msh" "$IN/swap.msh"
mv "$IN/swapdir" "$IN/swapdir.was" && ln -s "$OUT" "$IN/swapdir" && cp "$MESH" "$OUT/cyl.msh"
printf 'workers = 1\ninput_dir = %s\n' "$IN" >"$T/swap.conf"
kill -HUP "$DPID"
check swap_file_not_read wait_status "$S1" failed 120
check swap_file_reason grep -q 'leads outside its directory' "$T/st.json"
check swap_dir_not_read wait_status "$S2" failed 120
check unswapped_runs wait_status "$S3" successful 120
exit 0
