# t_76_draw.sh -- pictures (lensmat --draw, the imaging engine's drawing half):
# golden images of the document's Figures 4-7 and of the Cooke triplet (layout, spot
# diagram, ray fan), compared with a per-pixel threshold and a count of differing
# pixels; the comparison itself must catch a ray moved by a small field change; the
# drawn F2 tick sits at the paraxial F2 of the classic dialogue within one pixel;
# exact replay from the grep'd record (same record, same pictures); bad answers
# refused with FILE:LINE and nothing half-written; --trace's "draw" choice; and the
# start-up rule: classic, paraxial and tracing sessions map no OpenCV library, a
# --draw session does.
# GOLDEN_UPDATE=1 ONLY=t_76 sh tests/run.sh rewrites golden/images/ from this build.

unit "$TOP/build/obj/imaging_tests/t_draw"
unit "$TOP/build/asan/imaging_tests/t_draw"

DW=$WORK/draw
CMP=$TOP/build/obj/imaging_tests/draw_pngcmp
GI=$GOLDEN/images
RX=$TOP/doc/triplet.rx
mkdir -p "$DW"

# draw_session BIN DIR ANSWERS...: lensmat --draw in DIR, answers in DIR/in, stdout
# DIR/out, stderr DIR/err, record DIR/r.rec.
draw_session() {
    bin=$1; dir=$2; shift 2
    mkdir -p "$dir"
    printf '%s\n' "$@" > "$dir/in"
    (cd "$dir" && "$bin" --draw -i in r.rec > out 2> err)
}

# The sessions behind the golden images: Figures 4, 5, 6 (the golden classic cases,
# object 10 left of the lens, height 0.5), one refracting surface as Figure 7 (glass
# to the right edge) and the triplet at infinity, 14 degrees.
golden_sessions() {
    bin=$1; d=$2
    draw_session "$bin" "$d/f4" "$GOLDEN/cases/thick_r3_r4.in" 2.8 mm 10 0.5 0.8 layout fig4_layout.png done &&
    draw_session "$bin" "$d/f5" "$GOLDEN/cases/diverging_rm3_r3.in" 2.5 mm 10 0.5 0.5 layout fig5_layout.png done &&
    draw_session "$bin" "$d/f6" "$GOLDEN/cases/reversed_r1_rm3.in" 0.9 mm 10 0.5 0.8 layout fig6_layout.png done &&
    draw_session "$bin" "$d/f7" "$GOLDEN/cases/single_surface_gauss.in" 2.5 mm 14 1 0.6 layout fig7_layout.png done &&
    draw_session "$bin" "$d/tri" "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 14 1 \
        layout triplet_layout.png spot 587.6 triplet_spot.png fan triplet_fan.png done
}
GOLDEN_PICS="f4/fig4_layout f5/fig5_layout f6/fig6_layout f7/fig7_layout tri/triplet_layout tri/triplet_spot tri/triplet_fan"

if [ -n "$GOLDEN_UPDATE" ]; then
    golden_sessions "$BIN" "$DW/g" && mkdir -p "$GI" &&
    for p in $GOLDEN_PICS; do cp "$DW/g/$p.png" "$GI/"; done && echo "golden/images updated"
fi

# A picture matches its golden image: per pixel at most 48 apart in every channel,
# except at most 40 pixels (anti-aliasing, glyphs); a ray or label out of place
# changes hundreds.
same_picture() { "$CMP" cmp "$1" "$2" 48 40; }

golden_pictures() {
    golden_sessions "$1" "$DW/$2" || { cat "$DW/$2"/*/err; return 1; }
    for p in $GOLDEN_PICS; do
        gn=$(basename "$p")
        [ -s "$DW/$2/$p.svg" ] || { echo "no $p.svg"; return 1; }
        same_picture "$GI/$gn.png" "$DW/$2/$p.png" > "$DW/$2/cmp.$gn" ||
            { echo "$gn:"; cat "$DW/$2/cmp.$gn"; return 1; }
    done
}
check "draw: Figures 4-6 and the triplet's layout, spot and fan match golden/images" \
    golden_pictures "$BIN" run
check "draw asan: the golden pictures under ASan/UBSan" golden_pictures "$ASAN" asan

# The comparison is not blind: the triplet's rays filling 99 % of the first surface
# instead of all of it (every ray moved by under a pixel at the lens, a few at the
# image; the picture keeps its size) must fail it.
moved_ray_caught() {
    draw_session "$BIN" "$DW/moved" "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 14 0.99 \
        layout triplet_layout.png done || { cat "$DW/moved/err"; return 1; }
    if same_picture "$GI/triplet_layout.png" "$DW/moved/triplet_layout.png"; then
        echo "rays 1 % lower passed the golden comparison"; return 1; fi
    return 0
}
check "draw: the golden comparison catches rays 1 % lower at the lens" moved_ray_caught

# Geometry: the F2 tick the drawing reports is at x0 + scale * F2 with F2 the classic
# dialogue's second focal point (printed to 6 digits) within one pixel, and the
# picture's red pixels just above the axis there are centred on it within one pixel.
f2_geometry() {
    d=$DW/run/tri
    (cd "$DW" && "$BIN" --prescription -i "$RX" classic.rec > /dev/null) || return 1
    f2=$(sed -n 's/^Second focal point: z= \([^ ]*\).*/\1/p' "$DW/classic.rec")
    set -- $(sed -n 's/^Scale \([^ ]*\) pixels per mm; axis at pixel y \([^,]*\), z = 0 at pixel x \([^ ]*\) $/\1 \2 \3/p' "$d/out" | head -1)
    s=$1; y0=$2; x0=$3
    xf=$(sed -n 's/^  F2 at pixel x \([^ ]*\) .*/\1/p' "$d/out" | head -1)
    [ -n "$f2" ] && [ -n "$s" ] && [ -n "$xf" ] || { echo "f2=$f2 scale=$s F2 x=$xf"; return 1; }
    awk -v f2="$f2" -v s="$s" -v x0="$x0" -v xf="$xf" 'BEGIN {
        e = x0 + s * f2; d = xf - e; if (d < 0) d = -d
        printf "F2: classic z=%s -> pixel %.3f; drawn at %.3f\n", f2, e, xf; exit !(d <= 1) }' &&
    xp=$("$CMP" tick "$d/triplet_layout.png" "$xf" "$y0" 200 30 30) &&
    awk -v xp="$xp" -v xf="$xf" 'BEGIN { d = xp - xf; if (d < 0) d = -d
        printf "F2 tick pixels centred at %.3f\n", xp; exit !(d <= 1) }'
}
check "draw: the F2 tick is at the classic dialogue's F2 within one pixel, in the pixels too" f2_geometry

# Replay: the grep'd record gives the same record and the same pictures, byte for byte.
replay_same() {
    d=$DW/run/tri; r=$DW/replay
    mkdir -p "$r" && grep input: "$d/r.rec" > "$r/in" &&
    (cd "$r" && "$BIN" --draw -i in r.rec > out 2> err) || { cat "$r/err"; return 1; }
    cmp "$d/r.rec" "$r/r.rec" && cmp "$d/triplet_layout.png" "$r/triplet_layout.png" &&
    cmp "$d/triplet_spot.svg" "$r/triplet_spot.svg"
}
check "draw: the grep'd record replays exactly (record, PNG and SVG the same)" replay_same

svg_ok() {
    python3 -c 'import sys, xml.etree.ElementTree as E
for f in sys.argv[1:]:
    t = E.parse(f).getroot()
    assert t.tag.endswith("svg"), f
    texts = [e.text for e in t.iter() if e.tag.endswith("text")]
    assert texts, f' "$DW"/run/tri/*.svg &&
    grep -q '>F2</text>' "$DW/run/tri/triplet_layout.svg" &&
    grep -q '>20 mm</text>' "$DW/run/tri/triplet_layout.svg"
}
check "draw: the SVGs parse as XML and carry the labels and the scale bar" svg_ok

# The spot figures are the ones drawn: RMS about the centroid of the axial bundle
# under the geometric spot, Airy radius 0.61 lambda / NA' (about 2.7 um at f/4).
spot_figures() {
    d=$DW/run/tri
    grep -q '^Spot on the axis: [0-9]* hits, centroid (0, 0), RMS radius ' "$d/r.rec" &&
    sed -n 's/^Airy radius \([^ ]*\) .*/\1/p' "$d/r.rec" |
        awk '{ if (!($1 > 0.0024 && $1 < 0.0031)) { print "Airy radius " $1; exit 1 } }'
}
check "draw: spot statistics and the Airy radius are reported" spot_figures

# Bad answers: refused with FILE:LINE, exit 2 in a replay, never recorded, nothing
# written under a final name or left as a temporary file.
bad_answer() {   # bad_answer NAME EXPECTED-MESSAGE ANSWERS...
    bn=$1; bw=$2; shift 2
    d=$DW/bad/$bn; rm -rf "$d"
    if draw_session "$BIN" "$d" "$@"; then echo "exit 0"; return 1; fi
    cat "$d/err" "$d/out" | grep -q "$bw" || { echo "stderr:"; cat "$d/err"; return 1; }
    ! ls "$d" | grep -q 'part\|\.png$\|\.svg$' || { ls "$d"; return 1; }
}
mkdir -p "$DW/bad" "$DW/ro"
cp "$RX" "$DW/bad/lens.png"
check "draw bad: a missing lens file" bad_answer nofile "in:1: .*nothere.rx" nothere.rx
check "draw bad: a semi-diameter beyond a sphere's radius" bad_answer big \
    "in:2: .*surface 1 has radius 22.01359" "$RX" 30
check "draw bad: three semi-diameters for six surfaces" bad_answer count "in:2: .*6 positive" "$RX" 1,2,3
semis_refused() {
    for sd in '8,,8,8,8,8,8' '8,' ',8' nan -1 0 1e999 inf '8;8' '8,8,8,8,8,8,8'; do
        bad_answer "semi$(printf '%s' "$sd" | tr -c 'a-z0-9' _)" "in:2: .*6 positive" "$RX" "$sd" ||
            { echo "semi-diameters '$sd' not refused"; return 1; }
    done
}
check "draw bad: malformed semi-diameter lists" semis_refused
check "draw bad: a field angle of 85 degrees" bad_answer angle "in:5: .*under 80\|in:5: .*less than 80" \
    "$RX" 8 mm inf 85
check "draw bad: a picture name without .png" bad_answer nopng "in:8: .*must end in .png" \
    "$RX" 8 mm inf 0 1 layout pic.jpg
check "draw bad: the picture onto the lens file" bad_answer input "in:8: .*lens file this session reads" \
    ../lens.png 8 mm inf 0 1 layout ../lens.png
# the record named like a picture: lm_check_output refuses to draw over it
onto_record() {
    d=$DW/bad/rec; rm -rf "$d"; mkdir -p "$d"
    printf '%s\n' "$RX" 8 mm inf 0 1 layout r.png > "$d/in"
    if (cd "$d" && "$BIN" --draw -i in r.png > out 2> err); then echo "exit 0"; return 1; fi
    grep -q 'in:8: ' "$d/err" && grep -q '^input: layout$' "$d/r.png" &&
        ! grep -q 'input: r.png' "$d/r.png" || { cat "$d/err"; return 1; }
}
check "draw bad: the picture onto the record" onto_record
check "draw bad: a folder that cannot be written" bad_answer dir "in:8: .*cannot write" \
    "$RX" 8 mm inf 0 1 layout /proc/nothere/pic.png
check "draw bad: no picture of a virtual image's spot" bad_answer virtual "The picture cannot be drawn: the image is virtual" \
    "$GOLDEN/cases/thick_r3_r4.in" 2.8 mm 10 0 0.8 spot 0 v.png

# --trace's "draw" choice: pictures of the lens it just traced (and a polite refusal
# before anything was traced).
trace_draw() {
    d=$DW/trace
    trace_session "$BIN" "$d" draw y record "$RX" 5.5 inf 1 n y draw mm layout t.png \
        spot 0 s.png done n || { cat "$d/err"; return 1; }
    grep -q '^Nothing has been traced yet' "$d/r.rec" &&
    grep -q '^Pictures of the last lens traced: 6 surfaces $' "$d/r.rec" &&
    grep -q '^Written: t.png and t.svg (layout) $' "$d/r.rec" &&
    grep -q '^Written: s.png and s.svg (spot diagram) $' "$d/r.rec" &&
    "$CMP" tick "$d/t.png" $(sed -n 's/^  F2 at pixel x \([^ ]*\) .*/\1/p' "$d/out") \
        $(sed -n "s/.*axis at pixel y \([^,]*\),.*/\1/p" "$d/out") 200 30 30 > /dev/null
}
check "trace draw: --trace draws the layout and spot of the lens it traced" trace_draw

# Start-up: only a session that draws maps OpenCV (LD_DEBUG=files lists every object
# the loader maps, dlopen'ed modules included).
maps_opencv() {   # maps_opencv DIR OPTION ANSWERS...: 0 if the session mapped OpenCV
    d=$DW/maps/$1; opt=$2; shift 2
    mkdir -p "$d" && printf '%s\n' "$@" > "$d/in"
    (cd "$d" && LD_DEBUG=files "$BIN" $opt -i in r.rec > out 2> err)
    grep -q 'file=.*libopencv_core' "$d/err"
}
no_opencv_unless_drawing() {
    if maps_opencv classic "" $(cat "$GOLDEN/cases/thick_r3_r4.in"); then echo "classic mapped OpenCV"; return 1; fi
    if maps_opencv thick --thick 1 3 5 1.4 4 1 n; then echo "--thick mapped OpenCV"; return 1; fi
    if maps_opencv trace --trace record "$RX" 5.5 inf 1 n n; then echo "--trace mapped OpenCV"; return 1; fi
    grep -q 'lensmat-trace.so' "$DW/maps/trace/err" || { echo "the trace session did not even load the tracer"; return 1; }
    maps_opencv draw --draw "$RX" 8 mm inf 0 1 layout p.png done ||
        { echo "--draw did not map OpenCV"; tail -3 "$DW/maps/draw/err"; return 1; }
}
check "start-up: classic, --thick and --trace sessions map no OpenCV; --draw does" no_opencv_unless_drawing

# The tessellation table plotted: the record holds the (deterministic) errors, the
# times go to the terminal only, so the record replays exactly; the plot exists.
table_plot() {
    d=$DW/table
    draw_session "$BIN" "$d" "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 0 1 table tab.png done ||
        { cat "$d/err"; return 1; }
    [ -s "$d/tab.png" ] && [ -s "$d/tab.svg" ] &&
    [ "$(grep -c '^  mesh .*triangles  RMS error' "$d/r.rec")" -eq 18 ] &&
    ! grep -q 'trace .* ms' "$d/r.rec" && grep -q 'trace .* ms' "$d/out" &&
    grep -q '^  mesh +refine   128    196608 triangles  RMS error [0-9.]*e-1[0-9] ' "$d/r.rec" &&
    mkdir -p "$d/replay" && grep input: "$d/r.rec" > "$d/replay/in" &&
    (cd "$d/replay" && "$BIN" --draw -i in r.rec > out 2> err) && cmp "$d/r.rec" "$d/replay/r.rec"
}
check "draw: the tessellation table on log-log axes, record replays exactly" table_plot

# On a terminal: refused answers are explained and asked again, never recorded.
tty_draw() {
    python3 - "$BIN" "$DW/tty" "$RX" "$TOP/tests" <<'PYEOF'
import os, sys
bin_, d, rx = sys.argv[1:4]
sys.path.insert(0, sys.argv[4])
from ptydrive import drive
os.makedirs(d, exist_ok=True)
rc, out = drive([bin_, "--draw", "t.rec"],
                [rx.encode() + b"\n", b"30\n", b"8\n", b"mm\n", b"inf\n", b"0\n", b"1\n",
                 b"layout\n", b"pic.jpg\n", b"pic.png\n", b"done\n"], cwd=d, home=d, timeout=60)
rec = open(os.path.join(d, "t.rec")).read()
fails = []
if rc != 0: fails.append("exit %d" % rc)
if "surface 1 has radius 22.01359" not in out: fails.append("no re-ask for the semi-diameter")
if "must end in .png" not in out: fails.append("no re-ask for the picture name")
if "input: 30" in rec or "input: pic.jpg" in rec: fails.append("a refused answer was recorded")
if "Written: pic.png and pic.svg (layout)" not in rec: fails.append("record")
if not os.path.getsize(os.path.join(d, "pic.png")): fails.append("no picture")
print("\n".join(fails) or "ok", out[-800:] if fails else "")
sys.exit(1 if fails else 0)
PYEOF
}
if command -v python3 > /dev/null; then
    check "draw tty: a bad semi-diameter and picture name are asked again" tty_draw
fi

# SIGINT while the table is being traced: exit 130, no picture under its name and no
# temporary file.
interrupted() {
    d=$DW/sigint; rm -rf "$d"; mkdir -p "$d"
    printf '%s\n' "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 0 1 table tab.png done > "$d/in"
    (cd "$d" && exec "$BIN" --draw -i in r.rec > out 2> err) &
    pid=$!
    sleep 0.4
    kill -INT "$pid"
    wait "$pid"; rc=$?
    [ "$rc" -eq 130 ] || { echo "exit $rc"; return 1; }
    ! ls "$d" | grep -q 'tab\|part' || { ls "$d"; return 1; }
}
check "draw: SIGINT during a picture exits 130 and leaves no picture" interrupted

# The Airy radius of a small axial bundle (h = 0.3 x 8 mm) agrees with the paraxial
# 0.61 lambda f / h, f the classic dialogue's focal distance, to 1 %; and a bundle of
# 1 % of the aperture has a spot far under the Airy disc (spherical aberration ~ h^3).
airy_paraxial() {
    f=$(sed -n 's/^Second focal distance: \([^ ]*\).*/\1/p' "$DW/classic.rec")
    draw_session "$BIN" "$DW/airy" "$RX" 8 mm inf 0 0.3 spot 587.6 a.png done || return 1
    draw_session "$BIN" "$DW/tiny" "$RX" 8 mm inf 0 0.01 spot 587.6 a.png done || return 1
    a=$(sed -n 's/^Airy radius \([^ ]*\) .*/\1/p' "$DW/airy/r.rec")
    r=$(sed -n 's/^Spot on the axis: .* RMS radius \([^,]*\),.*/\1/p' "$DW/tiny/r.rec")
    t=$(sed -n 's/^Airy radius \([^ ]*\) .*/\1/p' "$DW/tiny/r.rec")
    awk -v a="$a" -v f="$f" -v r="$r" -v t="$t" 'BEGIN {
        p = 0.61 * 587.6e-6 * f / 2.4; d = (a - p) / p; if (d < 0) d = -d
        printf "Airy %s, paraxial %.6g (%.2g); tiny bundle RMS %s vs Airy %s\n", a, p, d, r, t
        exit !(d < 0.01 && r > 0 && r < 1e-3 * t) }'
}
check "draw: the Airy radius matches the paraxial 0.61 lambda f/h, tiny bundles spot inside it" airy_paraxial
