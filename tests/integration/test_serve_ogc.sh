#!/bin/sh
# test_serve_ogc.sh — OGC API – Processes conformance as third-party clients
# check it (ogc_conformance.py): OWSLib (Debian python3-owslib) discovery,
# urllib execute -> poll -> results, the job-list parameters, Prefer:
# respond-sync and response raw, the result digest and `packd submit --wait`.
# The per-input schemas are checked with python3-jsonschema by
# test_serve_input_schemas.sh.
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
PY=""
for py in python3 /usr/bin/python3; do
    "$py" -c 'import owslib.ogcapi.processes' 2>/dev/null && PY=$py && break
done
if [ -z "$PY" ]; then
    echo "SKIP test_serve_ogc: owslib cannot be imported (apt-get install python3-owslib; deploy/install-deps.sh)"
    exit 0
fi
start_daemon ogc --workers 2 || { fail serve_starts; exit 1; }
"$PY" "$SRC/tests/integration/ogc_conformance.py" "$B" "$PACKD" "$T" "$T/fast.json"
