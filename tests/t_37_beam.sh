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
