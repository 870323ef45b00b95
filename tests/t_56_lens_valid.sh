# t_56_lens_valid.sh -- lenses that cannot exist are refused where they are entered
# (src/lens/lens_shape.c, doc/files.md), with the same words in every dialogue: two
# spheres of radius 20 and -20, 2 apart, with semi-diameter 12 cross at
# h = sqrt(20^2 - 19^2) = 6.245 (closed form: sag(h) = 20 - sqrt(400 - h^2) on
# each side, 2 * sag = 2 gives 20 - sqrt(400 - h^2) = 1); a semi-diameter 25 on a
# sphere of radius 20 has no zone to stand on.  --pupil (lens file, FILE:LINE of the
# surface) and --draw (the semi-diameters' answer, FILE:LINE of the answer).
unit "$TOP/build/obj/unit_lens_shape"    # closed forms: sphere-sphere, sphere-plane
unit "$TOP/build/asan/unit_lens_shape"
LV=$WORK/lv56
lv_setup() {
    rm -rf "$LV"; mkdir -p "$LV"
    printf 'thickness\nindex air\n20 2 1.5 semi 12\n-20 5 air semi 12\n' > "$LV/cross.rx"
    printf 'thickness\nindex air\n20 8 1.5 semi 25\n-20 5 air semi 5\n' > "$LV/big.rx"
    printf 'thickness\nindex air\n20 2 1.5 semi 6\n-20 5 air semi 6\n' > "$LV/ok.rx"
    printf 'index 1\n20 0 1.5\n-20 2 1\nobject -100\n' > "$LV/cross.txt"
}
# the crossing height from the closed form, printed as lensmat prints it (%g)
H=$(awk 'BEGIN { printf "%g", sqrt(20 * 20 - 19 * 19) }')
lv_pupil() {   # FILE LINE MESSAGE
    lv_setup
    (cd "$LV" && printf '%s\n' "$1" > a.in && "$ASAN" --pupil -i a.in p.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$LV/err"; return 1; }
    grep -qF "lensmat: a.in:1: the lens file: $1:$2: $3" "$LV/err" || { cat "$LV/err"; return 1; }
}
check "--pupil: surfaces 1 and 2 cross at sqrt(20^2-19^2) with semi 12: refused at the file's line" \
    lv_pupil cross.rx 4 "surfaces 1 and 2 would cross at height $H (edge thickness -6 at the semi-diameter 12): give at most $H"
check "--pupil: semi 25 on a radius-20 sphere: refused at the file's line" \
    lv_pupil big.rx 3 "surface 1 has radius 20, so its semi-diameter can be at most 20 (not 25)"
lv_pupil_ok() {
    lv_setup
    (cd "$LV" && printf 'ok.rx\n1\nepd\n4\n1\n0\nhex\n2\nn\n' > a.in &&
     "$BIN" --pupil -i a.in p.rec > out 2> err) || { cat "$LV/err"; return 1; }
}
check "--pupil: the same lens with semi 6 is traced" lv_pupil_ok
lv_draw() {   # SEMI MESSAGE
    lv_setup
    (cd "$LV" && printf 'cross.txt\n%s\n' "$1" > d.in && "$ASAN" --draw -i d.in d.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$LV/err"; return 1; }
    grep -qF "lensmat: d.in:2: the semi-diameters: '$1': $2" "$LV/err" || { cat "$LV/err"; return 1; }
    # the record ends at the question: its answers replay to the same record
    grep input: "$LV/d.rec" > "$LV/d2.in"; (cd "$LV" && "$BIN" --draw -i d2.in d2.rec > /dev/null 2>&1)
    cmp "$LV/d.rec" "$LV/d2.rec"
}
check "--draw: semi 12 on the crossing lens refused at its answer, same words as --pupil" \
    lv_draw 12 "surfaces 1 and 2 would cross at height $H (edge thickness -6 at the semi-diameter 12): give at most $H"
check "--draw: semi 25 on a radius-20 sphere refused at its answer, same words" \
    lv_draw 25 "surface 1 has radius 20, so its semi-diameter can be at most 20 (not 25)"
# --wave reads its lens file through lensrx.c: the same refusal, the same words
lv_wave() {
    lv_setup
    (cd "$LV" && printf 'cross.rx\n' > w.in && "$ASAN" --wave -i w.in w.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$LV/err"; return 1; }
    grep -qF "lensmat: w.in:1: the lens file: cross.rx:4: surfaces 1 and 2 would cross at height $H" "$LV/err" ||
        { cat "$LV/err"; return 1; }
}
check "--wave: the crossing lens refused at the file's line, as --pupil refuses it" lv_wave
