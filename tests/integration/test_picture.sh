#!/bin/sh
# test_picture.sh — `packd picture`: real PNG files decoded back (zlib only)
# whose inked share of the box is the packing's φ (plus the outlines), SVG
# files that parse as XML, the 3D two-panel layout, the grading curve, and
# the errors a user meets.  The service's pictures are tested in test_serve.sh.
set -u
PACKD=${PACKD:-build/packd}
SRC=${PACKD_SRC:-.}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
. "$SRC/tests/integration/check.inc"

"$PACKD" run "$SRC/examples/meier-quartz-2d.json" -o "$T/q.h5" >/dev/null 2>&1
"$PACKD" picture "$T/q.h5" -o "$T/q.png"
# box panel: x from 36, y from 54, 720 px wide (api/picture/picture_packing.c); φ = 0.45
fill=$(python3 "$SRC/tests/tools/png_fill.py" "$T/q.png" 37 55 755 773)
check picture_2d_png_size test "$(echo "$fill" | cut -d' ' -f1-2)" = "792 810"
# outlines (0.4–0.9 px around 3–17 px disks) add up to ~0.07 of ink
check picture_2d_ink_is_phi python3 -c "f = float('$fill'.split()[2]); assert 0.45 <= f <= 0.55, f"
"$PACKD" picture "$T/q.h5" -o "$T/q.svg"
check picture_2d_svg python3 -c "
import xml.etree.ElementTree as E
r = E.parse('$T/q.svg').getroot(); assert r.tag.endswith('svg') and r.get('width').startswith('792'), r.attrib"
"$PACKD" picture "$T/q.h5" --kind grading -o "$T/g.svg"
check picture_grading_svg python3 -c "
import xml.etree.ElementTree as E; E.parse('$T/g.svg')"

# 3D: the mid-plane section beside the view along -z (two panels)
"$PACKD" run "$SRC/examples/din-a16-3d-walled.json" -o "$T/a.h5" >/dev/null 2>&1
"$PACKD" picture "$T/a.h5" -o "$T/a.png"
fill3=$(python3 "$SRC/tests/tools/png_fill.py" "$T/a.png" 37 55 755 773)
check picture_3d_two_panels test "$(echo "$fill3" | cut -d' ' -f1)" = 1548
# a section through grains at φ_eff = 0.316 inks about φ of the plane (area fraction = volume fraction)
check picture_3d_section_ink python3 -c "f = float('$fill3'.split()[2]); assert 0.25 <= f <= 0.42, f"

# errors
"$PACKD" picture "$T/q.h5" -o "$T/q.jpg" 2>"$T/e1"
check picture_refuses_unknown_format grep -q '.svg or .png' "$T/e1"
"$PACKD" picture "$T/missing.h5" -o "$T/m.png" 2>/dev/null
check picture_missing_file_exit_2 test $? -eq 2
"$PACKD" picture --help | grep -q 'usage: packd picture'
check picture_help test $? -eq 0
exit 0
