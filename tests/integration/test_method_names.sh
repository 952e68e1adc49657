#!/bin/sh
# test_method_names.sh — nothing outside a placer's own files decides by its
# name: no strcmp (or strncmp) against "rsa", "edmd", "tetfill" or any other
# placer of the table anywhere in core/, api/ or daemon/ but the placer's
# api/pack/pack_place_<name>.c and its core/<name>/ folder.  The shared code
# reads the placer's row instead (api/pack/pack_placer.h: capabilities,
# units, checks).  The names come from the placers' rows, so a new placer is
# covered without an edit here.
set -u
SRC=${PACKD_SRC:-$PWD}
. "$SRC/tests/integration/check.inc"
cd "$SRC" || exit 1

names=$(sed -n 's/.*\.name = "\([a-z0-9_]*\)".*/\1/p' api/pack/pack_place_*.c | sort -u)
check method_names_found test "$(echo "$names" | wc -w)" -ge 3
for n in $names; do
    hits=$(grep -rnE "str(n)?cmp\([^;]*\"$n\"" core api daemon --include='*.c' --include='*.h' |
        grep -v -e "^api/pack/pack_place_$n\.c:" -e "^core/$n/")
    check "no_strcmp_on_$n" test -z "$hits"
    [ -z "$hits" ] || echo "$hits" | head -5
done
