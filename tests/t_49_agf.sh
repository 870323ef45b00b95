# t_49_agf.sh -- Zemax AGF glass catalogues: the reader and the catalogue look-up
# (tests/unit_agf.c, on tests/agf/TEST*.agf: catalogues written for the tests with
# coefficients typed from SCHOTT's, OHARA's and Nikon-Hikari's published values),
# then through the dialogues with LENSMAT_GLASS_PATH: a prescription's `catalog` line,
# an AGF-only glass's focal lengths against a closed form, GCAT written back, a name
# in two catalogues said, an unknown catalogue refused with FILE:LINE, a broken
# catalogue file skipped and said, and no catalogue seen without the path.  Also the
# chromatic figure of issue 22 (tests/unit_chromatic.c), which needs N-BAK1.
unit "$TOP/build/obj/unit_agf"
unit "$TOP/build/asan/unit_agf"
# Laikin's achromat (tests/published/laikin_achromat.txt): the F-C focal shift by the
# paraxial engine, by real rays traced in the test, to first order; the peer's -0.015
unit "$TOP/build/obj/unit_chromatic"
unit "$TOP/build/asan/unit_chromatic"
AGF=$TOP/tests/agf

# OHARA S-BAL14 (the Sellmeier coefficients of tests/agf/TESTOHARA.agf, OHARA's
# catalogue 2017-11-30) in a biconvex lens R 50, t 5: 1/f = (n-1)(2/R - (n-1)t/(nR^2))
sbal14_f() {  # LAMBDA -> efl to 6 digits
    awk -v l="$1" 'BEGIN { l2 = l * l
        n2 = 1 + 1.27553696 * l2 / (l2 - 0.00749692359) + 0.146083393 * l2 / (l2 - 0.031042153)
        n = sqrt(n2 + 1.16754699 * l2 / (l2 - 128.947092))
        R = 50; t = 5; p = (n - 1) * (2 / R - (n - 1) * t / (n * R * R)); printf "%.6g", 1 / p }'
}
agf_rx() {
    bin=$1
    rm -rf "$WORK/ag" && mkdir -p "$WORK/ag" && cd "$WORK/ag" || return 1
    printf 'thickness\ncatalog TESTOHARA TESTSCHOTT\nwavelengths d F C\nepd 10\nfield angle 0\n50 5 S-BAL14 stop\n-50 45 air\n' > l.rx
    printf 'l.rx\nhex\n1\nn\n' > in
    LENSMAT_GLASS_PATH=$AGF "$bin" --pupil -i in p.rec > p.out 2> p.err || { cat p.err p.out; return 1; }
    for l in 0.5875618 0.4861327 0.6562725; do
        want=$(sbal14_f $l)
        nm=$(awk -v l=$l 'BEGIN { printf "%g", l * 1000 }')
        got=$(grep -A1 "^Wavelength $nm nm" p.out | sed -n 's/^  efl \([^,]*\),.*/\1/p')
        echo "S-BAL14 lens at $nm nm: efl want $want got $got"
        [ "$got" = "$want" ] || return 1
    done
    grep input: p.rec > in2 && LENSMAT_GLASS_PATH=$AGF "$bin" --pupil p2.rec < in2 > /dev/null 2>&1 &&
    cmp p.rec p2.rec
}
check "catalog TESTOHARA: S-BAL14's efl at d, F, C from OHARA's coefficients; replays" agf_rx "$BIN"
check "catalog TESTOHARA under ASan/UBSan" agf_rx "$ASAN"

agf_write() {
    cd "$WORK/ag" || return 1
    LENSMAT_GLASS_PATH=$AGF "$BIN" --to-zmx -i l.rx l.zmx 2> z.err || { cat z.err; return 1; }
    grep -q '^GCAT TESTOHARA TESTSCHOTT' l.zmx && grep -q '  GLAS S-BAL14 ' l.zmx || { cat l.zmx; return 1; }
    LENSMAT_GLASS_PATH=$AGF "$BIN" --to-thickness -i l.zmx l2.rx 2> t.err || { cat t.err; return 1; }
    grep -q '^catalog TESTOHARA TESTSCHOTT$' l2.rx && grep -q ' TESTOHARA:S-BAL14 ' l2.rx || { cat l2.rx; return 1; }
}
check "the catalogues are written back: GCAT in the .zmx, catalog and CATALOG:NAME in a prescription" agf_write

agf_two() {
    cd "$WORK/ag" || return 1
    printf 'thickness\ncatalog TESTSCHOTT LENSMAT\n50 5 N-BAK1\n-50 45 air\n' > two.rx
    LENSMAT_GLASS_PATH=$AGF "$BIN" --to-zmx -i two.rx two.zmx 2> two.err || { cat two.err; return 1; }
    grep -q "two.rx:3: glass N-BAK1 is in 2 catalogues (LENSMAT, TESTSCHOTT): TESTSCHOTT's is taken (the first selected catalogue that has it; their indices at F, d, C differ by up to 0.0e+00)" two.err ||
        { cat two.err; return 1; }
}
check "a glass in two catalogues: the one taken is said" agf_two

agf_unknown_cat() {
    cd "$WORK/ag" || return 1
    printf 'thickness\ncatalog NOPE\n50 5 N-BAK1\n-50 45 air\n' > u.rx
    LENSMAT_GLASS_PATH=$AGF "$BIN" --to-zmx -i u.rx u.zmx 2> u.err; rc=$?
    [ $rc -eq 2 ] && grep -q "u.rx:2: catalog NOPE: no such glass catalogue" u.err && [ ! -s u.zmx ]
}
check "catalog NOPE is refused with FILE:LINE, exit 2, no lens written" agf_unknown_cat

agf_broken() {
    rm -rf "$WORK/bk" && mkdir -p "$WORK/bk/cat" && cd "$WORK/bk" || return 1
    cp "$AGF/TESTOHARA.agf" cat/ && printf 'NM BAD 99 0 1.5 50 0 0 0\r\n' > cat/BROKEN.AGF
    printf 'thickness\n50 5 S-BAL14\n-50 45 air\n' > b.rx
    LENSMAT_GLASS_PATH=$WORK/bk/cat "$BIN" --to-zmx -i b.rx b.zmx 2> b.err || { cat b.err; return 1; }
    grep -q "glass catalogue skipped: $WORK/bk/cat/BROKEN.AGF:1: NM BAD: formula 99 is not one of the AGF formulas" b.err ||
        { cat b.err; return 1; }
    grep -q '  GLAS S-BAL14 ' b.zmx
}
check "a broken catalogue file is skipped and said, the others still read" agf_broken

agf_none() {
    cd "$WORK/ag" || return 1
    printf 'thickness\n50 5 S-BAL14\n-50 45 air\n' > n.rx
    env -u LENSMAT_GLASS_PATH "$BIN" --to-zmx -i n.rx n.zmx 2> n.err; rc=$?
    [ $rc -eq 2 ] && grep -q "n.rx:2: surface 1: glass S-BAL14 is neither in the catalogue" n.err
}
check "without the catalogue path S-BAL14 is unknown (refused, exit 2)" agf_none
