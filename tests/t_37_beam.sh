# t_37_beam.sh -- the --beam dialogue (Gaussian beams, section 46): the example's
# exact replay, the closed form of its first numbers, bad answers in a replay.  The
# arithmetic is checked against closed forms in tests/unit_beam.c.
unit "$TOP/build/obj/unit_beam"
unit "$TOP/build/asan/unit_beam"
BM=$WORK/beam; mkdir -p "$BM"
beam_replay() {
    (cd "$BM" && "$BIN" --beam --example a.rec > a.out && grep input: a.rec > a.in &&
     "$BIN" --beam b.rec < a.in > b.out && cmp a.rec b.rec)
}
# HeNe, w0 0.4 mm: zR = pi w0^2/lambda = 794.334 mm (closed form, awk)
beam_zr() {
    want=$(awk 'BEGIN { printf "%g", 3.14159265358979 * 0.4 * 0.4 / 632.8e-6 }')
    grep -q "Rayleigh range zR = pi n w0^2/(M^2 lambda) = $want," "$BM/a.rec"
}
beam_bad() {   # ANSWERS WANT_LINE: a replay stops at that line with exit 2
    printf "$1" > "$BM/bad.in"
    (cd "$BM" && "$BIN" --beam -i bad.in bad.rec > /dev/null 2> bad.err); rc=$?
    [ $rc -eq 2 ] && grep -q "bad.in:$2:" "$BM/bad.err" || { echo "exit $rc"; cat "$BM/bad.err"; return 1; }
}
check "--beam: the example replays exactly from its grep'd record" beam_replay
check "--beam: the Rayleigh range of the example is the closed form's" beam_zr
check "--beam: M^2 below 1 stops a replay at its line" beam_bad 'mm\n632.8\n0.5\n' 3
check "--beam: an element left of the previous one stops a replay at its line" \
    beam_bad 'mm\n632.8\n1\n1\n0.4\n0\nlens\n100\n50\nplane\n90\n' 11
check "--beam: a lens of focal length 0 stops a replay" beam_bad 'mm\n632.8\n1\n1\n0.4\n0\nlens\n100\n0\n' 9
check "--beam is listed by --help" sh -c "'$BIN' --help | grep -q -- '--beam'"
# The cornea as a convex mirror (R 7.8 mm, unfolded: f = -3.9 mm): a 1 mm waist on it
# leaves a virtual waist where Self's formula puts it, and the beam 100 mm on is the
# far-field closed form's (an independent awk model)
beam_cornea() {
    printf 'mm\n632.8\n1\n1\n1\n0\nmirror\n0\n7.8\nplane\n100\nend\n0\n' > "$BM/c.in"
    (cd "$BM" && "$BIN" --beam -i c.in c.rec > /dev/null) || return 1
    awk 'BEGIN { pi = 3.14159265358979; l = 632.8e-6; w0 = 1; f = -3.9
                 zr = pi * w0 * w0 / l; s = 0
                 s2 = 1 / (1 / f - 1 / (s + zr * zr / (s - f)))
                 m = 1 / sqrt((1 - s / f) ^ 2 + (zr / f) ^ 2); w1 = m * w0; zr1 = pi * w1 * w1 / l
                 w100 = w1 * sqrt(1 + ((100 - s2) / zr1) ^ 2)
                 printf "%.6g %.6g %.5g\n", s2, w1, w100 }' > "$BM/c.want"
    got=$(sed -n 's/^After it (index 1): waist w0= \([^ ]*\) at z= \([^,]*\),.*/\2 \1/p' "$BM/c.rec")
    got="$got $(sed -n 's/^At z= 100: beam radius w= \([^,]*\),.*/\1/p' "$BM/c.rec")"
    set -- $(cat "$BM/c.want"); zw=$1 w1=$2 w100=$3
    awk -v g="$got" -v zw="$zw" -v w1="$w1" -v w100="$w100" 'BEGIN {
        split(g, a, " ")
        ok = (a[1] - zw) ^ 2 < 1e-10 && ((a[2] - w1) / w1) ^ 2 < 1e-10 && ((a[3] - w100) / w100) ^ 2 < 1e-9
        if (!ok) printf "got %s, want waist at %s, w0 %s, w(100) %s\n", g, zw, w1, w100
        exit !ok }'
}
check "--beam: the cornea as a convex mirror (R 7.8 mm) against Self's formula and the far field" beam_cornea
