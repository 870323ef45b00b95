# t_66_trace_record.sh -- --trace's record choice: a lens read from a classic record,
# its grep'd answers or a prescription file, traced for real.  The paraxial image it
# reports must be the classic dialogue's image plane for the same object (to the
# classic's printed digits), the near-axis real ray must meet it to 1e-9 relative,
# a prescription of the same lens must give the same trace, malformed files stop a
# replay with FILE:LINE and exit 2 (re-asked on a terminal) without being recorded,
# and a session's record replays exactly.

RW=$WORK/trace-record
mkdir -p "$RW"


# The classic sessions the traces read (records made here, by this build): the golden
# doublet, and the golden thick lens R 3 / 4 with a second object (-10 images
# virtually, -40 really).
(cd "$RW" && "$BIN" doublet.rec < "$GOLDEN/cases/doublet_4surf.in" > /dev/null 2>&1 &&
    sed '$d' "$GOLDEN/cases/thick_r3_r4.in" > thick0.in && printf 'y\n-40\nn\n' >> thick0.in &&
    "$BIN" thick.rec < thick0.in > /dev/null 2>&1 && grep input: thick.rec > thick.in)

# same_images CLASSIC_REC TRACE_REC: every "Paraxial image" of the trace, rounded as
# the classic dialogue prints (%g), is the classic's "Image plane", in order, and
# there is one per object of the classic session.
same_images() {
    sed -n 's/^Image plane, z= \([^ ]*\).*/\1/p' "$1" > "$RW/img.classic"
    sed -n 's/^Paraxial image, z= \([^ ]*\).*/\1/p' "$2" |
        awk '{ printf "%g\n", $1 }' > "$RW/img.trace"
    [ -s "$RW/img.classic" ] || { echo "no image plane in $1"; return 1; }
    cmp "$RW/img.classic" "$RW/img.trace" || { paste "$RW/img.classic" "$RW/img.trace"; return 1; }
}

# near_axis_ok TRACE_REC N: N near-axis agreement lines, each under 1e-9 relative
near_axis_ok() {
    cnt=$(grep -c 'meets the paraxial image to' "$1")
    [ "$cnt" -eq "$2" ] || { echo "$cnt agreement lines, want $2"; return 1; }
    sed -n 's/.*meets the paraxial image to \([^ ]*\) relative.*/\1/p' "$1" |
        awk '{ if (!($1 < 1e-9)) { print "near-axis disagreement " $1; bad = 1 } } END { exit bad }'
}

# The doublet (4 surfaces) from its classic record; its objects at z = -30 and -100
# are 30 and 100 left of the first surface (z = 0), as the dialogue lists them.
record_doublet() {
    d=$RW/d; rm -rf "$d"
    trace_session "$1" "$d" record ../doublet.rec 2 30 1 y 100 0.5 n n || { cat "$d/err"; return 1; }
    [ ! -s "$d/err" ] || { cat "$d/err"; return 1; }
    grep -q '^Lens file: 4 surfaces, index left of the first surface 1 $' "$d/r.rec" &&
    grep -q '^Surface 3: radius -4.5, location 1.2, index right 1.6, semi-diameter 2 $' "$d/r.rec" &&
    grep -q '^Object planes of the file, as distances left of the first surface: 30 100$' "$d/r.rec" ||
        { echo "lens echo"; cat "$d/r.rec"; return 1; }
    same_images "$RW/doublet.rec" "$d/r.rec" && near_axis_ok "$d/r.rec" 2
}
check "trace record: doublet from a classic record, images = classic's, near axis < 1e-9" \
    record_doublet "$BIN"
check "trace record asan: doublet from a classic record" record_doublet "$ASAN"

# The thick lens from its grep'd answers: the virtual image is said so (no fan), the
# real one traced.
record_thick() {
    d=$RW/t; rm -rf "$d"
    trace_session "$BIN" "$d" record ../thick.in 2.5 10 0.8 y 40 0.8 n n || { cat "$d/err"; return 1; }
    grep -q '^Object planes of the file, as distances left of the first surface: 10 40$' "$d/r.rec" &&
        [ "$(grep -c '^The image is virtual' "$d/r.rec")" -eq 1 ] &&
        same_images "$RW/thick.rec" "$d/r.rec" && near_axis_ok "$d/r.rec" 1
}
check "trace record: thick lens from grep'd answers, images = classic's, virtual one said" record_thick

# A prescription of the doublet (written by --to-prescription) traces the same: the
# records agree from the lens on.
record_prescription() {
    d=$RW/p; rm -rf "$d"; mkdir -p "$d"
    "$BIN" --to-prescription -i "$RW/doublet.rec" "$d/doublet.lens" || return 1
    trace_session "$BIN" "$d" record doublet.lens 2 30 1 y 100 0.5 n n || { cat "$d/err"; return 1; }
    sed -n '/^Lens file:/,$p' "$RW/d/r.rec" > "$d/from-record"
    sed -n '/^Lens file:/,$p' "$d/r.rec" > "$d/from-prescription"
    [ -s "$d/from-record" ] && cmp "$d/from-record" "$d/from-prescription" &&
        same_images "$RW/doublet.rec" "$d/r.rec"
}
check "trace record: the doublet's prescription file traces as its record" record_prescription

# A hand-written prescription with a plane surface: the semi-diameter's limit is
# where the concave R -20 four units behind the plane meets it (sag -4 at 12), not
# the sphere's radius; the object at infinity.
record_plane() {
    d=$RW/pl; rm -rf "$d"; mkdir -p "$d"
    printf 'index 1\nplane 0 1.5\n-20 4 1\nobject -50\n' > "$d/pc.lens"
    trace_session "$BIN" "$d" record pc.lens 10 inf 1 n n || { cat "$d/err"; return 1; }
    grep -q 'at most 12: surfaces 1 and 2 cross above that height' "$d/r.rec" &&
        grep -q '^Surface 1: plane, location 0' "$d/r.rec" && near_axis_ok "$d/r.rec" 1
}
check "trace record: prescription with a plane surface, object at infinity" record_plane

# ---- malformed files: FILE:LINE, exit 2, the rejected name never recorded ----------
# rr_bad NAME FILE-CONTENT(printf format) MESSAGE [ANSWERS-AFTER-THE-NAME]
rr_bad() {
    d=$RW/bad; mkdir -p "$d"
    [ -n "$2" ] && printf "$2" > "$d/$1"
    (cd "$d" && printf "record\n%s\n$4" "$1" > "$1.in" &&
        "$BIN" --trace -i "$1.in" "$1.trace" > /dev/null 2> "$1.err")
    rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc, not 2"; cat "$d/$1.err"; return 1; }
    grep -qF "$3" "$d/$1.err" || { echo "message: want '$3'"; cat "$d/$1.err"; return 1; }
    if [ -z "$4" ]; then
        grep -qF "$1.in:2: the lens file: " "$d/$1.err" || { echo "answer line"; cat "$d/$1.err"; return 1; }
        ! grep -q "input: $1" "$d/$1.trace" || { echo "rejected name recorded"; return 1; }
    fi
}
check "trace record bad: a record with a bad radius" rr_bad badr.rec \
    'Enter the eye nearpoint\ninput: 25\ninput: 1\nEnter the radius\ninput: abc\n' \
    "badr.rec:5: the radius of the lens surface: 'abc': not a number"
check "trace record bad: answers ending early" rr_bad short.in '25\n1\n3\n0\n' \
    "short.in:5: end of input while asking for the index of refraction"
check "trace record bad: surfaces out of order" rr_bad order.in '25\n1\n3\n0\n1.5\ny\n-3\n-1\n' \
    "order.in:8: the location of the lens surface: '-1' lies left of the previous surface"
check "trace record bad: a prescription line" rr_bad bad.lens '# a lens\n3 0 1.5\n-3 0\nobject -2\n' \
    "bad.lens:3: a surface line needs three numbers"
check "trace record bad: a prescription with a negative index" rr_bad neg.lens 'index -1\n3 0 1.5\n' \
    "neg.lens:1: the index must be greater than 0"
rr_other() { cp "$RW/d/r.rec" "$RW/bad/trace.rec" &&
    rr_bad trace.rec '' "trace.rec: this is a record of lensmat --trace, not of the classic dialogue"; }
check "trace record bad: the record of another dialogue (--trace's own)" rr_other
check "trace record bad: a missing file" rr_bad nosuch.rec '' "nosuch.rec: cannot open"
rr_dir() { mkdir -p "$RW/bad/adir" && rr_bad adir '' "adir: not a regular file"; }
check "trace record bad: a folder" rr_dir
check "trace record bad: semi-diameter beyond the smallest radius" rr_bad ok.in \
    '25\n1\n3\n0\n1.5\ny\n-3\n6\n1\nn\n-5\nn\n' \
    "ok.in.in:3: the semi-diameter of the surfaces: '3.5' is larger than 3" '3.5\n'
# R 3 and -3 half a unit apart cross where 2 sag = 0.5 (s = 1.198957881); both at 0
# they touch on the axis and cross at any height: that file is refused at once.
check "trace record bad: semi-diameter where the surfaces cross" rr_bad cross.in \
    '25\n1\n3\n0\n1.5\ny\n-3\n0.5\n1\nn\n-5\nn\n' \
    "cross.in.in:3: the semi-diameter of the surfaces: '1.2': surfaces 1 and 2 cross above 1.198957881 (negative edge thickness)" '1.2\n'
check "trace record bad: surfaces touching on the axis and crossing" rr_bad touch.in \
    '25\n1\n3\n0\n1.5\ny\n-3\n0\n1\nn\n-5\nn\n' \
    "touch.in: surfaces 1 and 2 touch on the axis (at z= 0) and cross off it"

# ---- replay: record -> grep input: -> replay -> the same record ---------------------
replay_record() {
    d=$RW/rep; rm -rf "$d"; mkdir -p "$d"; cp "$RW/doublet.rec" "$RW/thick.in" "$d/" || return 1
    (cd "$d" && printf 'record\ndoublet.rec\n2\n30\n1\nn\ny\nrecord\nthick.in\n3\ninf\n1\nn\nn\n' > in &&
        "$1" --trace -i in a.rec > a.out 2> a.err && grep input: a.rec > in2 &&
        "$1" --trace b.rec < in2 > b.out 2> b.err) || { cat "$d/a.err" "$d/b.err"; return 1; }
    [ "$(grep -c '^input: ' "$d/a.rec")" -eq 14 ] || { echo "answers in the record"; return 1; }
    cmp "$d/a.rec" "$d/b.rec" || return 1
    for f in a b; do grep -v '^Output was written' "$d/$f.out" > "$d/$f.cmp"; done
    cmp "$d/a.cmp" "$d/b.cmp"
}
check "trace record replay: grep'd record replays to the same record" replay_record "$BIN"
check "trace record replay asan" replay_record "$ASAN"

# ---- on a terminal: a bad file is explained and asked again ---------------------------
tty_record() {
    python3 - "$BIN" "$RW/tty" "$RW/doublet.rec" "$TOP/tests" <<'EOF'
import os, shutil, sys
bin_, d, rec = sys.argv[1:4]
sys.path.insert(0, sys.argv[4])
from ptydrive import drive
os.makedirs(d, exist_ok=True)
shutil.copy(rec, os.path.join(d, "doublet.rec"))
with open(os.path.join(d, "broken.lens"), "w") as f: f.write("3 0 1.5\n-3 x 1\nobject -2\n")
rc, out = drive([bin_, "--trace", "t.rec"],
                [b"record\n", b"broken.lens\n", b"doublet.rec\n", b"9\n", b"2.17\n", b"30\n",
                 b"1\n", b"n\n", b"n\n"], cwd=d, home=d, timeout=60)
rec = open(os.path.join(d, "t.rec")).read()
fails = []
if rc != 0: fails.append("exit %d" % rc)
if "broken.lens:2: 'x' is not a number; please answer again" not in out: fails.append("no re-ask for the file")
if "'9': surfaces 1 and 2 cross above 2.179449472" not in out: fails.append("no re-ask for the semi-diameter")
if "broken" in rec or "input: 9" in rec: fails.append("a refused answer was recorded")
if "input: doublet.rec" not in rec or "meets the paraxial image" not in rec: fails.append("record")
print("\n".join(fails) or "ok", out[-800:] if fails else "")
sys.exit(1 if fails else 0)
EOF
}
if command -v python3 > /dev/null; then
    check "trace record tty: bad file and too large a semi-diameter are asked again" tty_record
fi
