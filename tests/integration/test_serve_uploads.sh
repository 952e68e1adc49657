#!/bin/sh
# test_serve_uploads.sh — uploads are data, never pages, and the daemon
# answers only to its own names: an HTML upload comes back as bytes to save
# (application/octet-stream, Content-Disposition: attachment, nosniff, a
# sandbox CSP); text/plain, form and untyped bodies to POST /files get 415
# before the body is read (a page of another site can send those); a request
# whose Host is not one of the daemon's names (DNS rebinding) gets 421 and
# nothing of it is echoed; allowed_hosts replaces the default names.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"

start_daemon uploads --workers 0 || { fail serve_starts; exit 1; }
PORT=${B##*:}

# an HTML page with a script, uploaded as text/html, is accepted as bytes ...
printf '<html><script>alert(document.domain)</script></html>' >"$T/page.html"
code=$(c -o "$T/up.json" -w '%{http_code}' -H 'Content-Type: text/html' --data-binary "@$T/page.html" "$B/files")
HREF=$(member "$T/up.json" href)
check html_upload_201 test "$code" = 201
# ... and goes back as an attachment that no browser renders or runs
c -D "$T/get.h" -o "$T/get.body" "$B$HREF"
hdr() { grep -i "^$1:" "$T/get.h" | tr -d '\r' | cut -d' ' -f2-; }
check html_served_as_octet_stream test "$(hdr Content-Type)" = application/octet-stream
check html_served_as_attachment sh -c "echo '$(hdr Content-Disposition)' | grep -q '^attachment'"
check html_served_nosniff test "$(hdr X-Content-Type-Options)" = nosniff
check html_served_sandboxed sh -c "echo \"$(hdr Content-Security-Policy)\" | grep -q '^sandbox'"
check html_bytes_unchanged cmp -s "$T/page.html" "$T/get.body"
# an HDF5 upload keeps its own type (it is data either way)
c -o "$T/h5.json" -H 'Content-Type: application/x-hdf5' --data-binary "@$T/up.json" "$B/files" >/dev/null
c -D "$T/get.h" -o /dev/null "$B$(member "$T/h5.json" href)"
check hdf5_served_as_hdf5 test "$(hdr Content-Type)" = application/x-hdf5

# bodies a cross-site form can send are refused, as on execution
code=$(c -o "$T/415.json" -w '%{http_code}' -H 'Content-Type: text/plain' --data-binary "@$T/page.html" "$B/files")
check files_text_plain_415 sh -c "test '$code' = 415 && grep -q 'Content-Type' '$T/415.json'"
code=$(c -o /dev/null -w '%{http_code}' --data-binary "@$T/page.html" "$B/files") # curl: urlencoded form
check files_form_415 test "$code" = 415
code=$(c -o /dev/null -w '%{http_code}' -F "f=@$T/page.html" "$B/files")
check files_multipart_415 test "$code" = 415
code=$(c -o /dev/null -w '%{http_code}' -H 'Content-Type:' --data-binary "@$T/page.html" "$B/files")
check files_untyped_415 test "$code" = 415
code=$(c -o /dev/null -w '%{http_code}' -H 'Content-Type: TEXT/PLAIN; charset=utf-8' \
    --data-binary "@$T/page.html" "$B/files")
check files_text_plain_charset_415 test "$code" = 415
# a type that is no printable ASCII (the http fuzz target's first find: the
# 201 document could not hold it and the daemon crashed)
code=$(c -o /dev/null -w '%{http_code}' -H "$(printf 'Content-Type: application/octet-st\377\377am')" \
    --data-binary "@$T/page.html" "$B/files")
check files_type_not_ascii_415 test "$code" = 415
check daemon_alive_after_bad_type test "$(c -o /dev/null -w '%{http_code}' "$B/healthz")" = 200

# a foreign Host name: 421 on every route, its name never echoed
rebind() { # path [curl args]: status with Host: rebind.attacker.example
    p=$1
    shift
    c -o "$T/rb.out" -D "$T/rb.h" -w '%{http_code}' -H 'Host: rebind.attacker.example' "$@" "$B$p"
}
check foreign_host_healthz_421 test "$(rebind /healthz)" = 421
check foreign_host_jobs_421 test "$(rebind /jobs)" = 421
check foreign_host_execute_421 test "$(rebind /processes/pack/execution -H 'Content-Type: application/json' \
    --data-binary "@$T/fast.json")" = 421
check foreign_host_not_echoed sh -c "! grep -qi attacker '$T/rb.h' '$T/rb.out'"
check foreign_host_port_421 test "$(rebind /files -H 'Host: evil.example:'"$PORT")" = 421
# the daemon's own names pass, with or without the port
for h in "127.0.0.1:$PORT" "localhost:$PORT" localhost "LOCALHOST." "[::1]:$PORT" "$(hostname)"; do
    check "own_host_200 ($h)" test "$(c -o /dev/null -w '%{http_code}' -H "Host: $h" "$B/healthz")" = 200
done
# an HTTP/1.0 request without Host passes
check no_host_http10_200 python3 -c "
import socket
s = socket.create_connection(('127.0.0.1', $PORT), timeout=5)
s.sendall(b'GET /healthz HTTP/1.0\\r\\n\\r\\n')
assert s.recv(64).split(b' ')[1] == b'200'"

# allowed_hosts replaces the default names; * allows any
start_daemon named --workers 0 --allowed-hosts 'packd.lab.example, 127.0.0.1' || exit 1
check allowed_name_200 test "$(c -o /dev/null -w '%{http_code}' -H 'Host: packd.lab.example' "$B/healthz")" = 200
check allowed_ip_200 test "$(c -o /dev/null -w '%{http_code}' "$B/healthz")" = 200
check unlisted_localhost_421 test "$(c -o /dev/null -w '%{http_code}' -H 'Host: localhost' "$B/healthz")" = 421
start_daemon any --workers 0 --allowed-hosts '*' || exit 1
check star_any_host_200 test "$(c -o /dev/null -w '%{http_code}' -H 'Host: anything.example' "$B/healthz")" = 200
exit 0
