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

# --colour: Thorlabs AC254-100-A (its embedded example; prescription from Thorlabs'
# Zemax file, see tests/unit_glass.c): efl at d 100.07 mm against Thorlabs' 100.1,
# the glasses' Vd as SCHOTT prints them, and an exact replay from the record.
colour_example() {
    cd "$WORK" && "$1" --colour --example col.rec > col.out || return 1
    grep -q '^  efl 100.07, ' col.rec || { grep efl col.rec; return 1; }
    grep -q 'Abbe number Vd of N-BK7: 64.17' col.rec && grep -q 'Abbe number Vd of SF5: 32.21' col.rec ||
        return 1
    grep -q 'longitudinal colour bfd(F) - bfd(C) = -0.119' col.rec || return 1
    # the Seidel sums' axial colour agrees with the F-C paraxial shift (first order)
    grep -q "axial colour -CI/(n'u'^2) = -0.118" col.rec || return 1
    [ "$(grep -c '^  [123] ' col.rec)" -eq 3 ] && grep -q '^  total ' col.rec || return 1
    grep input: col.rec > col.in && "$1" --colour col2.rec < col.in > /dev/null && cmp col.rec col2.rec
}
check "--colour: AC254-100-A example, efl 100.07, Vd, replay (lensmat)" colour_example "$BIN"
check "--colour: the same under ASan/UBSan" colour_example "$ASAN"
# a glass with no index at a wavelength of the session is refused with its range
colour_refuse() {   # colour_refuse NAME ANSWERS MESSAGE
    printf "$2" > "$WORK/cb.in"
    (cd "$WORK" && "$ASAN" --colour -i cb.in cb.rec > /dev/null 2> cb.err); rc=$?
    if [ "$rc" -eq 2 ] && grep -qF "$3" "$WORK/cb.err"; then pass "$1"
    else fail "$1 (exit $rc)"; cat "$WORK/cb.err"; fi
}
colour_refuse "--colour: diamond at C refused" 'mm\n2\nd\nC\nair\n1\n10\ndiamond\n' \
    "cb.in:8: the glass: DIAMOND: its formula holds from 0.226 to 0.644 um, not at wavelength 0.656273 um"
colour_refuse "--colour: 9 wavelengths refused" 'mm\n9\n' "cb.in:2: the number of wavelengths: '9': give 1 to 8"
colour_refuse "--colour: bad wavelength" 'mm\n1\nviolet\n' "'violet' is not a wavelength"
colour_refuse "--colour: unknown glass" 'mm\n1\nd\nair\n1\n10\nBK-7\n' "'BK-7' is not a glass lensmat knows"
# a singlet of a model glass: one wavelength, plane back, bfd = R/(n-1) at d
check "--colour: model-glass plano-convex, f = R/(n-1)" sh -c "
    cd '$WORK' && printf 'mm\n1\nd\nair\n2\n51.68\n1.5168/64.17\n0\nplane\nair\nn\n' > pc.in &&
    '$BIN' --colour -i pc.in pc.rec > /dev/null && grep -q '^  efl 100, ' pc.rec"

# Prescription files: an index field may be a glass; the classic record echoes it;
# --to-prescription reads such a record back (indices written as numbers, exact).
glass_prescription() {
    cd "$WORK" && printf '# index by glass\nindex air\n62.75 0 N-BK7\n-45.71 4 SF5@d\n-128.23 6.5 1\nobject -1000\n' > gp.rx &&
    "$1" --prescription -i gp.rx gp.rec > gp.out || return 1
    grep -q '^input: N-BK7$' gp.rec && grep -q '^input: SF5@d$' gp.rec || return 1
    grep -q '(SF5@d: index 1.672697 at 587.6 nm)' gp.rec || return 1
    "$1" --to-prescription -i gp.rec gp2.rx || return 1
    grep -q '^62.75  *0  *1.5168000345005885$' gp2.rx || { cat gp2.rx; return 1; }
    "$1" --prescription -i gp2.rx gp2.rec > /dev/null &&
        grep 'Image plane' gp.rec > a.img && grep 'Image plane' gp2.rec > b.img && cmp a.img b.img
}
check "prescription: glass names in index fields, record and back (lensmat)" glass_prescription "$BIN"
check "prescription: the same under ASan/UBSan" glass_prescription "$ASAN"
rx_refuse() {   # rx_refuse NAME LINE MESSAGE
    printf "$2\nobject 1\n" > "$WORK/rb.rx"
    (cd "$WORK" && "$ASAN" --prescription -i rb.rx rb.rec > /dev/null 2> rb.err); rc=$?
    if [ "$rc" -eq 2 ] && grep -qF "$3" "$WORK/rb.err"; then pass "$1"
    else fail "$1 (exit $rc)"; cat "$WORK/rb.err"; fi
}
rx_refuse "prescription: glass outside its range" '62.75 0 N-BK7@9' "rb.rx:1: N-BK7's formula holds from 0.3 to 2.5 um, not at 9 um"
rx_refuse "prescription: unknown glass" '62.75 0 BK-7' "rb.rx:1: 'BK-7' is not an index (a number, a medium, a glass"
# "wavelength W" in a prescription: every index named without "@" is taken at W
check "prescription: wavelength C applies to every glass named" sh -c "
    cd '$WORK' && printf 'wavelength C\n62.75 0 N-BK7\n-45.71 4 SF5\n-128.23 6.5 1.0\nobject -1000\n' > wl.rx &&
    '$ASAN' --prescription -i wl.rx wl.rec > /dev/null &&
    grep -q '^input: N-BK7@C\$' wl.rec && grep -q '^input: SF5@C\$' wl.rec && grep -q '^input: 1\$' wl.rec &&
    grep -q '(N-BK7@C: index 1.514322 at 656.3 nm)' wl.rec"
rx_refuse "prescription: wavelength after index" 'index 1\nwavelength C' "rb.rx:2: wavelength comes before index"
rx_refuse "prescription: bad wavelength" 'wavelength Z' "rb.rx:1: 'Z' is not a wavelength"
rx_refuse "prescription: wavelength twice" 'wavelength C\nwavelength d' "rb.rx:2: wavelength given twice"
rx_refuse "prescription: diamond at C" 'wavelength C\n1 0 diamond' "rb.rx:2: DIAMOND's formula holds from 0.226 to 0.644 um"

# Seidel sums (src/paraxial/seidel.c): exact-trace, thin-lens and axial-colour checks
unit "$TOP/build/obj/unit_seidel"
unit "$TOP/build/asan/unit_seidel"
colour_refuse "--colour: field angle beyond 60 degrees" 'mm\n1\nd\nair\n1\n10\nN-BK7\ny\n1\n70\n' \
    "cb.in:10: the field angle: the field angle must lie between -60 and 60 degrees"
