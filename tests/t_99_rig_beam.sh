# t_99_rig_beam.sh -- the laser's beam on the cornea and the detector (issue 21,
# rig_api.spots, --rig 'beam'): the engine against closed forms (tests/rig/t_spots.c:
# free space, Self's thin-lens formula, the cornea as a lens of focal length -R/2, a
# brute-force scan for the balancing lens, the photon count), both builds; the
# dialogue's report, its exact replay from the grep'd record, and a lens the geometry
# rules out refused at the rig file's line (exit 2).
for b in t_spots; do
    for d in obj asan; do
        x=$TOP/build/$d/rig_tests/$b
        if [ ! -x "$x" ]; then fail "$x (not built)"; continue; fi
        "$x" "$TOP/golden/rig/example.rig" > "$WORK/spots.out" 2>&1; rc=$?
        p=$(grep -c '^PASS' "$WORK/spots.out"); f=$(grep -c '^FAIL' "$WORK/spots.out")
        PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
        grep '^FAIL' "$WORK/spots.out" | sed "s|^|$b ($d): |"
        [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || fail "$b ($d) exited $rc"
    done
done
D=$WORK/rigbeam
mkdir -p "$D"
beam_session() {   # beam_session DIR RIG: the beam report on the simulator
    mkdir -p "$1"
    printf '%s\n' "$2" sim - beam quit > "$1/in"
    (cd "$1" && "$BIN" --rig -i in r.rec > out 2> err)
}
beam_report() {
    beam_session "$D/a" "$TOP/golden/rig/example.rig" || return 1
    grep -q 'waist of radius 0.2 mm (beam_diameter_mm / 2) at the cornea apex' "$D/a/r.rec" &&
        grep -q 'cornea 0.2 mm, detector 3.534 mm' "$D/a/r.rec" &&
        grep -q '^Balanced lens .* f 36.0' "$D/a/r.rec" &&
        grep -q '^Centroid (shot noise only): 200 ms' "$D/a/r.rec"
}
check "rig beam: the report for the example rig" beam_report
beam_replay() {
    grep input: "$D/a/r.rec" > "$D/a/in2"
    (cd "$D/a" && "$BIN" --rig r2.rec < in2 > /dev/null 2>&1) && cmp "$D/a/r.rec" "$D/a/r2.rec"
}
check "rig beam: the grep'd record replays exactly" beam_replay
check "rig beam: ASan build, the same session" sh -c "cd '$D/a' && LENSMAT_LIBDIR='$TOP/build/asan/lib' '$ASAN' --rig r3.rec < in2 > /dev/null 2>&1 && cmp r.rec r3.rec"
beam_bad() {
    cp "$TOP/golden/rig/example.rig" "$D/far.rig"
    echo "focus_lens_mm 50 500" >> "$D/far.rig"
    n=$(wc -l < "$D/far.rig")
    beam_session "$D/b" "$D/far.rig"; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; return 1; }
    grep -q "far.rig:$n: 'focus_lens_mm': the lens 500 mm before the apex is not on the m2-cornea leg" "$D/b/err"
}
check "rig beam: a lens off the m2-cornea leg is refused at its rig-file line" beam_bad
beam_badkey() {
    cp "$TOP/golden/rig/example.rig" "$D/m2.rig"
    echo "beam_m2 0.9" >> "$D/m2.rig"
    n=$(wc -l < "$D/m2.rig")
    beam_session "$D/c" "$D/m2.rig"; rc=$?
    [ "$rc" -eq 2 ] && grep -q "m2.rig:$n: 'beam_m2' must be from 1 to 1000" "$D/c/err"
}
check "rig beam: beam_m2 below 1 is refused at FILE:LINE" beam_badkey
