# t_39_lensfile.sh -- the lens model's files (src/lens, issue 14): the unit tests
# (tests/unit_lens.c: thickness prescriptions and .zmx read, written, read again;
# Thorlabs' files against their published EFL and BFL), then the dialogues:
# --prescription on a .zmx (UTF-8 and UTF-16) and on a thickness prescription gives
# an ordinary classic record that replays from its grep'd answers; what the classic
# cannot take is said; --to-zmx / --to-thickness convert every golden classic session
# and the Thorlabs files, and the conversions reach a fixed point; bad files are
# refused with FILE:LINE and exit 2; an output never overwrites its input.
unit "$TOP/build/obj/unit_lens"
unit "$TOP/build/asan/unit_lens"
ZMX=$TOP/tests/zmx

# lf_classic BIN FILE: --prescription on FILE; the record replays; focal distance 100.07
lf_classic() (   # a subshell: its cd stays inside
    bin=$1; f=$2
    rm -rf "$WORK/lf"; mkdir -p "$WORK/lf"; cd "$WORK/lf" || return 1
    "$bin" --prescription -i "$f" a.rec > a.out 2> a.err || { cat a.err; return 1; }
    grep -q '^Focal distance: 100.07 $' a.out || { echo "no focal distance 100.07"; return 1; }
    grep -q 'not used: 2 more wavelength(s), semi-diameters (3 surfaces), the stop (surface 1), the aperture (epd 22.86)' a.err ||
        { echo "the extras are not stated:"; cat a.err; return 1; }
    grep -q 'not read (display, tolerancing' a.err || { echo "no note of what was not read"; return 1; }
    grep input: a.rec > in
    "$bin" b.rec < in > b.out 2> b.err || return 1
    cd "$TOP" && cmp "$WORK/lf/a.rec" "$WORK/lf/b.rec"
)
check "--prescription on Thorlabs' AC254-100-A.zmx: classic record, extras stated, replays" \
    lf_classic "$BIN" "$ZMX/AC254-100-A.zmx"
check "--prescription on the .zmx under ASan/UBSan" lf_classic "$ASAN" "$ZMX/AC254-100-A.zmx"
lf_utf16() (   # a subshell: its cd stays inside
    { printf '\377\376'; iconv -f UTF-8 -t UTF-16LE "$ZMX/AC254-100-A.zmx"; } > "$WORK/u16.zmx" &&
    lf_classic "$BIN" "$WORK/u16.zmx"
)
check "--prescription on the .zmx as OpticStudio writes it (UTF-16LE, BOM)" lf_utf16

# the same lens through --to-thickness: the thickness file gives the same record
lf_thickness() (   # a subshell: its cd stays inside
    rm -rf "$WORK/lt"; mkdir -p "$WORK/lt"; cd "$WORK/lt" || return 1
    "$BIN" --to-thickness -i "$ZMX/AC254-100-A.zmx" t.rx 2> t.err || { cat t.err; return 1; }
    grep -q '^62.75  *4  *N-BK7 semi 12.7 stop$' t.rx || { echo "surface 1 is not 62.75 4 N-BK7 semi 12.7 stop:"; cat t.rx; return 1; }
    grep -q '^wavelengths 0.5876 0.4861 0.6563$' t.rx || { cat t.rx; return 1; }
    "$BIN" --prescription -i "$ZMX/AC254-100-A.zmx" z.rec > /dev/null 2>&1 &&
    "$BIN" --prescription -i t.rx t.rec > /dev/null 2> e.txt || { cat e.txt; return 1; }
    cd "$TOP" && cmp "$WORK/lt/z.rec" "$WORK/lt/t.rec"
)
check "--to-thickness of the .zmx: 62.75 4 N-BK7 semi 12.7 stop; the same classic record" lf_thickness

# conversions reach a fixed point: zmx -> rx -> zmx -> rx -> zmx -> rx: the .zmx
# written twice the same bytes, and the prescription (a lens without fields gains the
# on-axis field OpticStudio needs in the first .zmx, so from the second rx on)
lf_fixpoint() (   # a subshell: its cd stays inside
    f=$1
    rm -rf "$WORK/lx"; mkdir -p "$WORK/lx"; cd "$WORK/lx" || return 1
    "$BIN" --to-thickness -i "$f" a.rx 2> /dev/null &&
    "$BIN" --to-zmx -i a.rx b.zmx 2> /dev/null &&
    "$BIN" --to-thickness -i b.zmx c.rx 2> /dev/null &&
    "$BIN" --to-zmx -i c.rx d.zmx 2> /dev/null &&
    "$BIN" --to-thickness -i d.zmx e.rx 2> /dev/null || return 1
    cmp b.zmx d.zmx && cmp c.rx e.rx
)
for f in "$ZMX"/*.zmx; do
    check "conversions of $(basename "$f") reach a fixed point" lf_fixpoint "$f"
done

# every golden classic session: record -> .zmx -> --prescription gives the same
# cardinal points as the session (positions become thicknesses and back)
lf_golden() (   # a subshell: its cd stays inside
    rec=$1
    rm -rf "$WORK/lg"; mkdir -p "$WORK/lg"; cd "$WORK/lg" || return 1
    "$BIN" --to-zmx -i "$rec" g.zmx 2> /dev/null || return 1
    "$BIN" --prescription -i g.zmx g.rec > /dev/null 2>&1 || { echo "g.zmx does not run"; return 1; }
    grep -E '^(Principal|Nodal) plane|focal point|Focal distance' "$rec" | sed 's/ *$//' > want
    grep -E '^(Principal|Nodal) plane|focal point|Focal distance' g.rec | sed 's/ *$//' > got
    # a session's first surface may not be at z = 0: compare the focal distances only
    grep 'Focal distance' want > w2; grep 'Focal distance' got > g2
    cd "$TOP" && cmp "$WORK/lg/w2" "$WORK/lg/g2"
)
for f in "$GOLDEN"/cases/convex_thin_doc.rec "$GOLDEN"/cases/doublet_4surf.rec; do
    check "--to-zmx of golden $(basename "$f" .rec): the same focal distances" lf_golden "$f"
done

# bad files: FILE:LINE, exit 2, nothing run
lf_bad() (   # a subshell: its cd stays inside
    want=$1; shift
    printf "$@" > "$WORK/bad.zmx"
    "$BIN" --prescription -i "$WORK/bad.zmx" "$WORK/bad.rec" > /dev/null 2> "$WORK/bad.err"
    rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; return 1; }
    grep -q "$want" "$WORK/bad.err" || { cat "$WORK/bad.err"; return 1; }
)
check "a .zmx mirror in glass (Mangin) is refused with its line" lf_bad \
    'bad.zmx:6: a mirror in N-BK7 (a Mangin mirror) is not supported' \
    'VERS 1\nMODE SEQ\nSURF 0\nSURF 1\n  GLAS N-BK7\nSURF 2\n  GLAS MIRROR 0 0\nSURF 3\n'
check "a thickness file's bad key is refused with its line" lf_bad "bad.zmx:2: 'semi' needs a value" \
    'thickness\n10 2 N-BK7 semi\n-10 40 air\n'
check "an unknown glass is refused with its line" lf_bad "bad.zmx:2: surface 1: glass NOPE" \
    'thickness\n10 2 NOPE\n-10 40 air\n'

# the classic prescription keeps its reading (a positions file runs as before)
lf_old() (   # a subshell: its cd stays inside
    rm -rf "$WORK/lo"; mkdir -p "$WORK/lo"; cd "$WORK/lo" || return 1
    "$BIN" --prescription --example a.rec > /dev/null 2>&1 || return 1
    "$BIN" --to-thickness -i a.rec t.rx 2>/dev/null && "$BIN" --prescription -i t.rx b.rec > /dev/null 2>&1 || return 1
    grep 'Focal distance\|Image plane' a.rec > w; grep 'Focal distance\|Image plane' b.rec > g
    cd "$TOP" && cmp "$WORK/lo/w" "$WORK/lo/g"
)
check "section 13's prescription by thickness: the same focal distances and images" lf_old

lf_same_file() (   # a subshell: its cd stays inside
    cp "$ZMX/AC254-100-A.zmx" "$WORK/same.zmx"
    ! "$BIN" --to-zmx -i "$WORK/same.zmx" "$WORK/same.zmx" 2> /dev/null &&
    cmp "$WORK/same.zmx" "$ZMX/AC254-100-A.zmx"
)
check "--to-zmx refuses to write over its input" lf_same_file
check "--to-zmx --example and --to-thickness --example run" sh -c "cd '$WORK' &&
    '$BIN' --to-zmx --example ex.zmx 2>/dev/null && grep -q '^SURF 4' ex.zmx &&
    '$BIN' --to-thickness --example ex.rx 2>/dev/null && grep -q '^field angle 0 5$' ex.rx"

# --trace reads a .zmx as a lens file (through the same classic answers)
lf_trace() (   # a subshell: its cd stays inside
    [ -f "$TOP/build/lib/lensmat-trace.so" ] || { echo "trace module not built"; return 1; }
    rm -rf "$WORK/ltr"; mkdir -p "$WORK/ltr"; cd "$WORK/ltr" || return 1
    printf 'record\n%s\n10\n1000\n1\nn\nn\n' "$ZMX/AC254-100-A.zmx" > in
    "$BIN" --trace -i in t.rec > out 2> err || { cat err; return 1; }
    grep -q '^Surface 2: radius -45.71, location 4, index right 1.672693462, semi-diameter 10' out &&
    grep -q '^Near the axis (height 1e-05) the real trace meets the paraxial image' out
)
check "--trace takes Thorlabs' .zmx as its lens file" lf_trace
