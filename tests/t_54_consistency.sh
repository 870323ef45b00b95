# t_54_consistency.sh -- what a user notices across dialogues (doc/files.md): a file
# name typed with a blank and no quotes is refused with the quoting rule (replay:
# FILE:LINE, exit 2; the record holds no half of it); a record of another dialogue
# given where a lens is read says which dialogue made it; make example builds the
# engine modules a first --trace needs.
CS=$WORK/cs54
cs_setup() { rm -rf "$CS"; mkdir -p "$CS"; cp "$TOP/doc/pupil-triplet.rx" "$CS/my lens.rx";
             cp "$TOP/doc/pupil-triplet.rx" "$CS/my"; }
two_words() {   # OPTION ANSWERS-BEFORE...: the file question gets `my lens.rx`
    opt=$1; shift
    cs_setup
    (cd "$CS" && { [ $# -eq 0 ] || printf '%s\n' "$@"; printf 'my lens.rx\n'; } > a.in &&
     "$ASAN" "$opt" -i a.in r.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$CS/err"; return 1; }
    grep -qF "a.in:$(($# + 1)): " "$CS/err" &&
        grep -qF "'my' and then 'lens.rx' on the same line: a file name that holds a blank must be quoted (\"my lens.rx\")" "$CS/err" ||
        { cat "$CS/err"; return 1; }
    ! grep -q '^input: my$' "$CS/r.rec"
}
check "--pupil: an unquoted 'my lens.rx' is refused with the quoting rule" two_words --pupil
check "--draw: the same at its lens-file question" two_words --draw
check "--trace: the same at its scene question" two_words --trace scene
quoted_ok() {
    cs_setup
    (cd "$CS" && printf '"my lens.rx"\ngrid\n12\ny\n5\n' > a.in && "$BIN" --pupil -i a.in r.rec > out 2> err) ||
        { cat "$CS/err"; return 1; }
    grep -qF 'input: "my lens.rx"' "$CS/r.rec"
}
check "--pupil: the quoted \"my lens.rx\" is read" quoted_ok
# a record of another dialogue where a lens is asked
other_record() {   # DIALOGUE-OF-THE-RECORD READER ANSWERS-AFTER
    cs_setup
    (cd "$CS" && "$BIN" "$1" --example other.rec > /dev/null 2>&1 &&
     printf 'other.rec\n' > a.in && "$BIN" "$2" -i a.in r.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$CS/err"; return 1; }
    grep -qF "a.in:1: the lens file: other.rec: this is a record of lensmat $1, not of the classic dialogue" "$CS/err" ||
        { cat "$CS/err"; return 1; }
}
check "--draw given a --thick record: says --thick made it" other_record --thick --draw
check "--draw given a --colour record: says --colour made it" other_record --colour --draw
other_record_prescription() {
    cs_setup
    (cd "$CS" && "$BIN" --thin --example other.rec > /dev/null 2>&1 &&
     "$BIN" --to-prescription -i other.rec r.rx > out 2> err); rc=$?
    [ $rc -eq 2 ] && grep -qF "other.rec: this is a record of lensmat --thin" "$CS/err"
}
check "--to-prescription -i a --thin record: says --thin made it" other_record_prescription
classic_record_still_read() {
    cs_setup
    (cd "$CS" && "$BIN" --example c.rec > /dev/null && "$BIN" --to-prescription -i c.rec c.rx > /dev/null 2> err &&
     grep -q '^index ' c.rx) || { cat "$CS/err"; return 1; }
}
check "a classic record is still read as a lens" classic_record_still_read

# make example: builds the modules (a dry run lists them in its recipe)
make_example_modules() {
    make -n -C "$TOP" example 2> /dev/null > "$CS/make.n"
    for m in trace imaging fit; do
        grep -q "build/lib/lensmat-$m.so" "$CS/make.n" || { echo "make example does not build lensmat-$m.so"; return 1; }
    done
}
cs_setup
check "make example builds the engine modules (trace, imaging, fit), not only ./lensmat" make_example_modules

# one reader: an answers file mixing input: lines and plain answers replays in the
# classic dialogue and is read by every lens reader (--to-thickness, --to-prescription)
mixed_answers() {
    cs_setup
    (cd "$CS" && "$BIN" --example c.rec > /dev/null &&
     grep input: c.rec | sed 's/^input: //' | awk 'NR % 2 == 0 { print "input: " $0; next } { print }' > mixed.in &&
     grep -q '^input: ' mixed.in && grep -qv '^input: ' mixed.in &&
     "$BIN" -i mixed.in c2.rec > /dev/null && cmp c.rec c2.rec &&
     "$BIN" --to-prescription -i c.rec want.rx > /dev/null 2>&1 &&
     "$BIN" --to-prescription -i mixed.in got.rx > /dev/null 2> err && cmp want.rx got.rx &&
     "$BIN" --to-thickness -i c.rec want.t > /dev/null 2>&1 &&
     "$BIN" --to-thickness -i mixed.in got.t > /dev/null 2>> err && cmp want.t got.t) ||
        { cat "$CS/err"; return 1; }
}
check "an answers file mixing input: lines and plain answers: one reader everywhere" mixed_answers

# air: 1.000293 in the classic dialogue (and the calculations, positions
# prescriptions), 1 in lens files by thickness, .zmx and the catalogue (--colour,
# --pupil); each says which applies where air is accepted
air_classic() {
    cs_setup
    (cd "$CS" && printf '25\nair\n1\n0\n1.5\nn\n' > a.in && "$BIN" -i a.in a.rec > a.out 2>/dev/null)
    grep -qF '(air: index 1.000293, air at 589 nm, as this dialogue and positions prescriptions take it; lens files by thickness, .zmx and --colour take air as 1)' "$CS/a.rec" &&
        grep -qF '(air: index 1.000293' "$CS/a.out" &&
        grep -q '^input: air$' "$CS/a.rec" &&
        grep input: "$CS/a.rec" > "$CS/a2.in" && (cd "$CS" && "$BIN" -i a2.in a2.rec > /dev/null 2>&1); cmp "$CS/a.rec" "$CS/a2.rec"
}
check "air in the classic dialogue: 1.000293, and it says lens files take 1" air_classic
air_numbers_unchanged() {   # a numeric answer's bytes are those of golden/
    cs_setup
    (cd "$CS" && "$BIN" -i "$GOLDEN/cases/convex_thin_doc.in" c.rec > c.out) && cmp "$CS/c.rec" "$GOLDEN/cases/convex_thin_doc.rec"
}
check "air: numeric classic sessions keep golden/'s bytes" air_numbers_unchanged
air_colour_pupil() {
    cs_setup
    (cd "$CS" && "$BIN" --colour --example co.rec > /dev/null && "$BIN" --pupil --example p.rec > /dev/null 2>&1 ||
        { cd "$CS" && ln -s "$TOP/doc" doc && "$BIN" --pupil --example p.rec > /dev/null; })
    grep -qF "(air: index 1, the glass catalogue's AIR, as in lens files; the classic dialogue's air is 1.000293)" "$CS/co.rec" &&
        grep -qF "Air: index 1 (in lens files indices are relative to air, as in OpticStudio; the classic dialogue's air is 1.000293)" "$CS/p.rec" &&
        grep -q 'indices: air 1.000000 ' "$CS/co.rec"
}
check "air in --colour and --pupil: 1, and each says so" air_colour_pupil

# --to-zmx / --to-thickness of a typed classic session: a named glass keeps its name
# (and so its dispersion), thicknesses are the typed positions' exact differences
# (doc/triplet.rx's positions: 10.26623 - 9.2666 = 0.99963, not 0.9996299999999998)
typed_triplet() {
    cs_setup
    printf '25\n1\n22.01359\n0\nN-SK16\ny\n-435.76044\n3.25896\n1\ny\n-22.21328\n9.2666\nF2\ny\n20.29192\n10.26623\n1\ny\n79.6836\n15.01664\nN-SK16\ny\n-18.39533\n17.96872\n1\nn\n-1000\nn\n' > "$CS/tri.in"
    (cd "$CS" && "$BIN" -i tri.in tri.rec > /dev/null && "$BIN" --to-thickness -i tri.rec tri.rx &&
     "$BIN" --to-zmx -i tri.rec tri.zmx) 2> "$CS/err" || { cat "$CS/err"; return 1; }
    grep -q '^-22.21328  *0.99963  *F2$' "$CS/tri.rx" && grep -q '^22.01359  *3.25896  *N-SK16$' "$CS/tri.rx" &&
        ! grep -q '99999\|00000000' "$CS/tri.rx" || { cat "$CS/tri.rx"; return 1; }
    grep -q '^  GLAS F2 ' "$CS/tri.zmx" && grep -q '^  DISZ 0.99963' "$CS/tri.zmx" &&
        ! grep -q 'GLAS ___BLANK 1 0 1.62' "$CS/tri.zmx" || { grep 'GLAS\|DISZ' "$CS/tri.zmx"; return 1; }
}
check "--to-thickness, --to-zmx of a typed session: glass names kept, thicknesses as typed" typed_triplet

# on a terminal: `my lens.rx` unquoted is explained and asked again, never recorded
two_words_tty() {
    cs_setup
    python3 - "$BIN" "$CS" "$TOP/tests" <<'PYEOF'
import os, sys
bin_, d = sys.argv[1:3]
sys.path.insert(0, sys.argv[3])
from ptydrive import drive
rc, out = drive([bin_, "--pupil", "t.rec"],
                [b"my lens.rx\n", b"\"my lens.rx\"\n", b"grid\n", b"4\n", b"n\n"],
                cwd=d, home=d, timeout=60)
rec = open(os.path.join(d, "t.rec")).read()
fails = []
if rc != 0: fails.append("exit %d" % rc)
if "must be quoted (\"my lens.rx\")" not in out or "please answer again" not in out:
    fails.append("no re-ask with the quoting rule")
if "input: my\n" in rec: fails.append("half of the name was recorded")
if "input: \"my lens.rx\"" not in rec: fails.append("the quoted name was not read")
print("\n".join(fails) or "ok", out[-800:] if fails else "")
sys.exit(1 if fails else 0)
PYEOF
}
command -v python3 > /dev/null &&
    check "--pupil on a terminal: 'my lens.rx' unquoted is asked again with the quoting rule" two_words_tty
