# t_38_glass.sh -- glasses by name wherever an index is asked: the catalogue's
# published values and the per-wavelength engine (tests/unit_glass.c), then answers
# "N-BK7", "F2@C", "1.5168/64.17@632.8" in the classic dialogue and a calculation
# dialogue, their exact replay, the classic's bytes for numbers and media, and the
# refusals (FILE:LINE, exit 2).

unit "$TOP/build/obj/unit_glass"
unit "$TOP/build/asan/unit_glass"

for b in "$BIN" "$ASAN"; do  # both builds
    sed_in='25\n1\n3\n0\nn-bk7@f\ny\n-3\n0\n1\nn\n-2\nn\n'
    check "glass: n-bk7@f answered, echoed N-BK7@F, replays exactly (${b#$TOP/})" \
        sh -c "printf '$sed_in' > '$WORK/gin' && cd '$WORK' && '$b' -i gin gr.rec > gout &&
               grep -q '^input: N-BK7@F\$' gr.rec && grep input: gr.rec > gin2 &&
               '$b' gr2.rec < gin2 > /dev/null && cmp gr.rec gr2.rec &&
               grep -q '(N-BK7@F: index 1.522376 at 486.1 nm)' gout"
done

# A glass by name gives the same record numbers as its index typed as a number: the
# image plane of the lens with N-BK7 (nd 1.516800 at d to 6 decimals) and 1.5168.
check "glass: N-BK7 at d images as 1.5168 does" sh -c "
    cd '$WORK' && printf '25\n1\n3\n0\nN-BK7\ny\n-3\n0\n1\nn\n-2\nn\n' > a.in &&
    printf '25\n1\n3\n0\n1.5168\ny\n-3\n0\n1\nn\n-2\nn\n' > b.in &&
    '$BIN' -i a.in a.rec > a.out && '$BIN' -i b.in b.rec > b.out &&
    grep 'Image plane' a.out > a.img && grep 'Image plane' b.out > b.img && cmp a.img b.img"

# A bare medium's name keeps the classic's constant and line: water is 1.333.
check "glass: bare 'water' is still the classic's 1.333" sh -c "
    cd '$WORK' && printf '25\nwater\n' | '$BIN' w.rec 2>/dev/null | grep -q '(water: index 1.333)'"
check "glass: water@d takes Daimon-Masumura's formula" sh -c "
    cd '$WORK' && printf '25\nwater@d\n' | '$BIN' w.rec 2>/dev/null |
    grep -q '(WATER@d: index 1.333403 at 587.6 nm)'"

# Model glass nd/Vd in a calculation dialogue (--thick asks indices too).
check "glass: model glass 1.5168/64.17 in --thick" sh -c "
    cd '$WORK' && printf 'cm\n1\n10\n0.5\n1.5168/64.17\n-10\n1\nn\n' > t.in &&
    '$BIN' --thick -i t.in t.rec > t.out && grep -q '^input: 1.5168/64.17\$' t.rec &&
    grep -q '(1.5168/64.17: index 1.516800 at 587.6 nm)' t.out"

# Refusals: replay stops at FILE:LINE with the reason, exit 2.
refuse() {   # refuse NAME ANSWER MESSAGE
    printf '25\n%s\n' "$2" > "$WORK/bad.in"
    (cd "$WORK" && "$ASAN" -i bad.in bad.rec > /dev/null 2> bad.err); rc=$?
    if [ "$rc" -eq 2 ] && grep -qF "bad.in:2: " "$WORK/bad.err" && grep -qF "$3" "$WORK/bad.err"
    then pass "$1"; else fail "$1 (exit $rc)"; cat "$WORK/bad.err"; fi
}
refuse "glass: N-BK7 at 3 um refused" 'N-BK7@3' "N-BK7's formula holds from 0.3 to 2.5 um, not at 3 um"
refuse "glass: silicon at d refused" 'silicon@d' "SILICON's formula holds from 1.36 to 11 um"
refuse "glass: unknown glass after @" 'unobtainium@d' "'unobtainium' is not a glass lensmat knows"
refuse "glass: bad wavelength" 'N-BK7@blue' "'blue' is not a wavelength"
refuse "glass: bad model glass" '0.5/64' "'0.5/64' is neither a catalogue glass nor a model glass"
refuse "glass: model glass outside 0.36-1 um" '1.5/60@2000' "a model glass holds from 0.36 to 1 um"
refuse "glass: unknown word" 'glas' "'glas' is not a number, nor a medium or glass"

# The catalogue generator refuses a malformed line with its FILE:LINE.
check "glass: gen_glass.sh refuses a bad line" sh -c "
    printf 'X sellmeier 0.3 2.5 1.5 60 1 2 3\n' > '$WORK/bad.txt' &&
    ! sh '$TOP/scripts/gen_glass.sh' '$WORK/bad.txt' '$WORK/bad.h' 2> '$WORK/gen.err' &&
    grep -q 'bad.txt:1: coefficients must come in pairs' '$WORK/gen.err' && [ ! -f '$WORK/bad.h' ]"
