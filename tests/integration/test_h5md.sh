#!/bin/sh
# test_h5md.sh — the result files follow H5MD 1.1 (tests/tools/h5md_check.py,
# docs/result-format.md): a result of each process (pack by RSA, EDMD and
# tet filling; homogenize) has time-dependent elements with step, time and
# value of one length, a scalar ASCII unit string on every dimensional
# dataset, the units module, connectivity [n][2] with its particles group;
# /h5md/author names who ran it: $USER or --author for `packd run`, the job's
# owner (the token's name) for a service job, "unknown" when no person is
# known (no $USER; a service job without auth, whose owner is an address).
. "${PACKD_SRC:-.}/tests/integration/serve_helpers.inc"
EX="$SRC/examples"
CHECK="$SRC/tests/tools/h5md_check.py"

cd "$T" || exit 1
for j in homogenize/rve-rsa-2d edmd-quartz-2d tetfill-box; do
    n=$(basename "$j")
    if (cd "$SRC" && USER=carol "$PACKD" run "$EX/$j.json" -o "$T/$n.h5" >/dev/null 2>"$T/$n.err"); then
        check "h5md_$n" python3 "$CHECK" "$T/$n.h5" --author carol
    else
        fail "h5md_$n" "$(head -c 300 "$T/$n.err")"
    fi
done
cp rve-rsa-2d.h5 rve-2d.h5
USER=carol "$PACKD" run "$EX/homogenize/homogenize-periodic-2d.json" -o hom.h5 >/dev/null 2>hom.err ||
    fail h5md_homogenize_runs "$(head -c 300 hom.err)"
check h5md_homogenize python3 "$CHECK" hom.h5 --author carol
# the homogenize result keeps the RVE's length unit and states the stress in N per length
check h5md_homogenize_units sh -c "h5dump -a /particles/grains/position/unit hom.h5 | grep -q '\"mm\"' &&
    h5dump -a /observables/homogenize/P/value/unit hom.h5 | grep -q '\"N mm-1\"' &&
    h5dump -a /observables/homogenize/E_n/unit hom.h5 | grep -q '\"N mm-1\"'"
check h5md_homogenize_shapes sh -c "h5dump -H -d /observables/homogenize/P/value hom.h5 | grep -q '( 20, 2, 2 )' &&
    h5dump -H -d /connectivity/contacts hom.h5 | grep -q ', 2 ) /' &&
    h5dump -H -d /observables/homogenize/final_state/position hom.h5 | grep -q '( 150, 2 )'"
# without $USER nor --author nobody is known: the name says "unknown", not the program
USER= "$PACKD" run "$EX/homogenize/rve-rsa-2d.json" -o anon.h5 >/dev/null 2>&1
check h5md_author_without_user python3 "$CHECK" anon.h5 --author unknown
USER=carol "$PACKD" run "$EX/homogenize/rve-rsa-2d.json" -o named.h5 --author "Carol Meier" >/dev/null 2>&1
check h5md_author_option python3 "$CHECK" named.h5 --author "Carol Meier"

# a service job without auth: its owner is only the client's address, no person
start_daemon open || { fail open_serve_starts; exit 1; }
ID=$(submit "$T/fast.json")
st() { c -o "$T/st.json" "$B/jobs/$ID" && member "$T/st.json" status; }
ok() { [ "$(st)" = successful ]; }
check open_job_successful wait_for 60 ok
c -o "$T/open.h5" "$B/jobs/$ID/results/result"
check h5md_service_without_owner_unknown python3 "$CHECK" "$T/open.h5" --author unknown

# a service job: its owner (the token's name) is the author
D="$T/auth"
tok=$("$PACKD" token add dora --data "$D" 2>/dev/null)
printf 'Authorization: Bearer %s\n' "$tok" >"$T/dora.h"
printf 'auth = on\nworkers = 1\n' >"$T/auth.conf"
start_daemon auth --config "$T/auth.conf" || { fail serve_starts; exit 1; }
ID=$(submit "$T/fast.json" -H "@$T/dora.h")
st() { c -H "@$T/dora.h" -o "$T/st.json" "$B/jobs/$ID" && member "$T/st.json" status; }
ok() { [ "$(st)" = successful ]; }
check service_job_successful wait_for 60 ok
c -H "@$T/dora.h" -o "$T/svc.h5" "$B/jobs/$ID/results/result"
check h5md_service_author_is_owner python3 "$CHECK" "$T/svc.h5" --author dora
