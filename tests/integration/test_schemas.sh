#!/bin/sh
# test_schemas.sh — cross-check schemas/ and examples/ with an independent
# validator (Debian's python3-jsonschema), so our own validator is never the
# only judge of our own schemas.
for py in /usr/bin/python3 python3; do
    if "$py" -c 'import jsonschema' 2>/dev/null; then
        exec "$py" tools/check-schemas.py
    fi
done
echo "FAIL check_schemas: python3-jsonschema is not installed (deploy/install-deps.sh installs it)"
exit 1
