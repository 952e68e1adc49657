#!/bin/sh
# test_picture.sh — `packd picture`: real PNG files decoded back (zlib only)
# whose inked share of the box is the packing's φ (plus the outlines), SVG
# files that parse as XML, the 3D two-panel layout (a tetfill result's mesh
# edges in its section), the grading curve, the
# plots (EDMD history, homogenization stress and residual: coloured curves
# across the plot area), the worker's picture set, and the errors a user
# meets.  The service's pictures are tested in test_serve.sh.
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
check picture_2d_png_size test "$(echo "$fill" | cut -d' ' -f1-2)" = "962 846"
# right of the panel a swatch and the diameters of each size class (coloured
# swatches: 6 of the 7 classes were placed); below it the scale bar
legend=$(python3 "$SRC/tests/tools/png_fill.py" "$T/q.png" 792 54 962 230 colour)
check picture_2d_size_legend python3 -c "f = float('$legend'.split()[2]); assert f > 0.005, f"
bar=$(python3 "$SRC/tests/tools/png_fill.py" "$T/q.png" 36 815 156 835)
check picture_2d_scale_bar python3 -c "f = float('$bar'.split()[2]); assert f > 0.05, f"
# outlines (0.4–0.9 px around 3–17 px disks) add up to ~0.07 of ink
check picture_2d_ink_is_phi python3 -c "f = float('$fill'.split()[2]); assert 0.45 <= f <= 0.55, f"
"$PACKD" picture "$T/q.h5" -o "$T/q.svg"
check picture_2d_svg python3 -c "
import xml.etree.ElementTree as E
r = E.parse('$T/q.svg').getroot(); assert r.tag.endswith('svg') and r.get('width').startswith('962'), r.attrib"
"$PACKD" picture "$T/q.h5" --kind grading -o "$T/g.svg"
check picture_grading_svg python3 -c "
import xml.etree.ElementTree as E; E.parse('$T/g.svg')"

# 3D: the mid-plane section beside the view along -z (two panels)
"$PACKD" run "$SRC/examples/din-a16-3d-walled.json" -o "$T/a.h5" >/dev/null 2>&1
"$PACKD" picture "$T/a.h5" -o "$T/a.png"
fill3=$(python3 "$SRC/tests/tools/png_fill.py" "$T/a.png" 37 55 755 773)
check picture_3d_two_panels test "$(echo "$fill3" | cut -d' ' -f1)" = 1718
# a section through grains at φ_eff = 0.316 inks about φ of the plane (area fraction = volume fraction)
check picture_3d_section_ink python3 -c "f = float('$fill3'.split()[2]); assert 0.25 <= f <= 0.42, f"
# a tetfill result: its tet mesh where the section cuts it, outlined in dark red (one
# closed polygon per cut tet); a packing without a mesh has none
(cd "$SRC" && "$PACKD" run examples/tetfill-box.json -o "$T/tb.h5" >/dev/null 2>&1)
"$PACKD" picture "$T/tb.h5" -o "$T/tb.svg" && "$PACKD" picture "$T/a.h5" -o "$T/a.svg"
mesh_cuts() { # FILE.svg: closed polygons of the mesh's stroke colour
    python3 -c "
import re, sys
print(sum(p.count('Z') for p in re.findall(r'stroke:rgb\(70%,10%,10%\)[^>]*d=\"([^\"]*)\"', open(sys.argv[1]).read())))" "$1"
}
check picture_tetfill_mesh_section python3 -c "n = $(mesh_cuts "$T/tb.svg"); assert n >= 20, n"
check picture_no_mesh_without_tetfill test "$(mesh_cuts "$T/a.svg")" = 0

# plots: PNG curves reach across the plot area (coloured pixels in >= 80 % of
# its columns; a legend alone spans < 40 %), SVG parses.  Plot areas (api/picture/
# picture_history.c, picture_homog.c): x 80..670 (history) or 80..730, y 50..420.
svg_parses() { python3 -c "import xml.etree.ElementTree as E, sys; E.parse(sys.argv[1])" "$1"; }
plot_ok() { # NAME FILE.h5 KIND RIGHT
    "$PACKD" picture "$2" --kind "$3" -o "$T/$3.png" 2>"$T/$3.err" &&
        "$PACKD" picture "$2" --kind "$3" -o "$T/$3.svg" 2>>"$T/$3.err"
    check "$1_drawn" test $? -eq 0
    cols=$(python3 "$SRC/tests/tools/png_fill.py" "$T/$3.png" 82 48 "$4" 424 colour)
    check "$1_png_curves" python3 -c "w, h, f, c = '$cols'.split(); assert float(c) >= 0.8 and float(f) > 0.003, '$cols'"
    check "$1_svg" svg_parses "$T/$3.svg"
}
# EDMD (its worker picture set too: the plots whose data the result holds)
mkdir "$T/pics"
(cd "$SRC" && "$PACKD" run examples/edmd-quartz-2d.json -o "$T/e.h5" --pictures "$T/pics" >/dev/null 2>&1)
plot_ok picture_history "$T/e.h5" history 668
check picture_set_has_history test -s "$T/pics/history.png" -a -s "$T/pics/history.svg" -a -s "$T/pics/grading.png"
check picture_set_skips_homogenize_plots test ! -e "$T/pics/stress.png" -a ! -e "$T/pics/residual.svg"
# homogenization (the RVE made first, in $T where the example reads it)
(cd "$T" && "$PACKD" run "$SRC/examples/homogenize/rve-rsa-2d.json" -o rve-2d.h5 >/dev/null 2>&1 &&
    "$PACKD" run "$SRC/examples/homogenize/homogenize-periodic-2d.json" -o h.h5 >/dev/null 2>&1)
plot_ok picture_stress "$T/h.h5" stress 728
plot_ok picture_residual "$T/h.h5" residual 728

# errors
# a plot asked of a result without its data names what is missing
"$PACKD" picture "$T/q.h5" --kind history -o "$T/x.png" 2>"$T/e2"
check picture_history_needs_edmd test $? -eq 2 -a -n "$(grep 'has no placer history' "$T/e2")"
"$PACKD" picture "$T/e.h5" --kind stress -o "$T/x.svg" 2>"$T/e3"
check picture_stress_needs_homogenize test $? -eq 2 -a -n "$(grep 'has no stress-strain data' "$T/e3")"
"$PACKD" picture "$T/q.h5" --kind residual -o "$T/x.png" 2>"$T/e4"
check picture_residual_needs_homogenize test $? -eq 2 -a -n "$(grep 'has no residual history' "$T/e4")"
check picture_no_file_left_by_a_refusal test ! -e "$T/x.png" -a ! -e "$T/x.svg"
"$PACKD" picture "$T/q.h5" --kind nosuch -o "$T/x.png" 2>"$T/e5"
check picture_unknown_kind_lists_kinds test $? -eq 64 -a -n "$(grep 'residual' "$T/e5")"
"$PACKD" picture "$T/q.h5" -o "$T/q.jpg" 2>"$T/e1"
check picture_refuses_unknown_format grep -q '.svg or .png' "$T/e1"
"$PACKD" picture "$T/missing.h5" -o "$T/m.png" 2>/dev/null
check picture_missing_file_exit_2 test $? -eq 2
"$PACKD" picture --help | grep -q 'usage: packd picture'
check picture_help test $? -eq 0
exit 0
