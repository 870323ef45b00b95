# t_35_paraxial.sh -- the paraxial engine: the extreme-prescription suite (C, both
# builds), and the classic dialogue's use of it: in default mode, where the original's
# arithmetic is not accurate to the printed digits (a 200-surface chain whose entries
# reach 1e9) the accurate value is printed, and ill-conditioned results get a note;
# --original keeps the old bytes.
unit "$TOP/build/obj/unit_paraxial_extreme"
unit "$TOP/build/asan/unit_paraxial_extreme"

# px_session NAME MODE: run $WORK/NAME.in, record in $WORK/NAME$MODE.rec
px_session() {
    (cd "$WORK" && "$BIN" $2 "$1$2.rec" < "$1.in" > "$1$2.out")
}
# px_changed NAME PATTERN: the default and --original records differ, and only in
# lines matching PATTERN (added note lines included)
px_changed() {
    px_session "$1" "" && px_session "$1" --original || return 1
    diff "$WORK/$1--original.rec" "$WORK/$1.rec" > "$WORK/$1.diff" && return 1
    ! grep '^[<>]' "$WORK/$1.diff" | grep -Ev "^[<>] ($2)"
}

# 200 surfaces, deterministic, entries growing past 1e9 (see the README example)
awk 'BEGIN { print 25; print 1; z = 0
    for (i = 0; i < 200; i++) {
        r = (4 + 8 * (0.5 + 0.5 * sin(i * 1.7))) * ((i % 3) ? 1 : -1)
        n = 1.3 + 0.4 * (0.5 + 0.5 * sin(i * 2.3 + 1))
        if (i) z += 0.8 + 4.5 * (0.5 + 0.5 * sin(i * 0.9 + 2))
        printf "%.6g\n%.6g\n%.6g\n%s\n", r, z, n, (i < 199 ? "y" : "n") }
    print -40; print "n" }' > "$WORK/chain.in"
check "classic default: accurate focal distances and magnification on a 200-surface chain" \
    px_changed chain 'First focal distance|Second focal distance|Magnification, z=|Nodal plane'
check "classic default: the chain's magnification is -3.67656e-11 (the original: 4.76837e-07)" \
    sh -c "grep -q '^Magnification, z= -3.67656e-11 $' '$WORK/chain.rec' &&
           grep -q '^Magnification, z= 4.76837e-07 $' '$WORK/chain--original.rec'"

# thin lens f = 3, object 1e-9 from the focal plane; then 1 ulp from it
printf '25\n1\n3\n0\n1.5\ny\n-3\n0\n1\nn\n-3.000000001\ny\n-3.0000000000000004\nn\n' \
    > "$WORK/nearfocus.in"
check "classic default: image of an object 1e-9 from the focal plane flagged ill-conditioned" \
    px_changed nearfocus '  \(ill-conditioned: relative condition 2.4e\+10'
check "classic: an object 1 ulp from the focal plane images at infinity" \
    grep -q "Image plane at infinity" "$WORK/nearfocus.rec"

# telescope f = 100, 10 detuned by 1e-9: focal, every cardinal point flagged
printf '25\n1\n100\n0\n1.5\ny\n-100\n0\n1\ny\n10\n110.000000001\n1.5\ny\n-10\n110.000000001\n1\nn\n-1000\nn\n' \
    > "$WORK/detuned.in"
check "classic default: cardinal points of a nearly afocal telescope flagged" \
    sh -c "cd '$WORK' && '$BIN' d.rec < detuned.in > /dev/null &&
           [ \$(grep -c '  (ill-conditioned: relative condition' d.rec) -eq 8 ] &&
           '$BIN' --original o.rec < detuned.in > /dev/null &&
           ! grep -q 'ill-conditioned' o.rec"

# detuned by 5e-13 (a few ulps of 110): still focal, but no digit of the principal
# planes survives: "undetermined" instead of a number, in default mode only
printf '25\n1\n100\n0\n1.5\ny\n-100\n0\n1\ny\n10\n110.0000000000005\n1.5\ny\n-10\n110.0000000000005\n1\nn\n-1000\nn\n' \
    > "$WORK/hopeless.in"
check "classic default: results with no digit left print 'undetermined'" \
    sh -c "cd '$WORK' && '$BIN' h.rec < hopeless.in > /dev/null &&
           grep -q '^Principal plane 1, z= undetermined (relative condition' h.rec &&
           '$BIN' --original ho.rec < hopeless.in > /dev/null &&
           grep -Eq '^Principal plane 1, z= -?[0-9.e+]+ $' ho.rec"
