#!/bin/sh
# test_serve_input_schemas.sh — a third-party client (Debian's
# python3-jsonschema) takes each input's schema from the served process
# description alone and validates every example's value of that input:
# the schemas must be self-contained (their $refs resolve inside them).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
PY=""
for py in /usr/bin/python3 python3; do
    "$py" -c 'import jsonschema' 2>/dev/null && PY=$py && break
done
[ -n "$PY" ] || { fail input_schemas_standalone "python3-jsonschema is not installed"; exit 1; }
start_daemon d || { fail serve_starts; exit 1; }
c "$B/processes/pack" >"$T/pack.json"
c "$B/processes/homogenize" >"$T/homogenize.json"
c "$B/processes/fe2" >"$T/fe2.json"
check input_schemas_standalone "$PY" - "$T" "$SRC/examples" <<'PYEOF'
import glob, json, os, sys
from jsonschema import validators
T, ex = sys.argv[1], sys.argv[2]
docs = {p: json.load(open(os.path.join(T, p + ".json"))) for p in ("pack", "homogenize", "fe2")}
checked = 0
for path in sorted(glob.glob(ex + "/*.json") + glob.glob(ex + "/*/*.json")):
    job = json.load(open(path))
    doc = docs.get(job.get("process"))
    if doc is None:
        continue
    for name, value in job["inputs"].items():
        schema = doc["inputs"][name]["schema"]
        cls = validators.validator_for(schema)
        cls.check_schema(schema)
        cls(schema).validate(value)  # raises on an unresolvable $ref or an invalid value
        checked += 1
# and a wrong value is refused by the standalone schema
schema = docs["pack"]["inputs"]["domain"]["schema"]
cls = validators.validator_for(schema)
assert list(cls(schema).iter_errors({"box": {"size": "big"}})), "domain schema accepted garbage"
assert checked > 20, checked
print("checked", checked, "inputs")
PYEOF
exit 0
