# t_17_session.sh -- the session and the command line as a new user meets them (issue
# 8): a terminal on stdin stays interactive when stdout is piped; --example shows its
# answers; messages escape control bytes; NUL bytes, leftovers on later lines, quoted
# file names, BOM and comment lines; outputs never over inputs; --input=F, --,
# --original where it means nothing; a missing engine module said up front.
S=$WORK/s17; mkdir -p "$S"
CIN=$GOLDEN/cases/convex_thin_doc.in

if command -v python3 > /dev/null; then
    mkdir -p "$S/tty"
    check "tty: stdin a terminal, stdout a pipe: still interactive (re-ask), prompts piped" \
        python3 "$TOP/tests/tty_pipe.py" "$BIN" "$S/tty"
fi

check "--example shows each answer after its question; the record is unchanged" sh -c "
    cd '$S' && '$BIN' --example ex.rec > ex.out && cmp ex.rec '$GOLDEN/cases/convex_thin_doc.rec' &&
    grep -A1 '^Enter the eye nearpoint' ex.out | tail -n 1 | grep -qx 25 &&
    [ \$(grep -c '^input: ' ex.rec) -eq \$(grep -cxFf '$CIN' ex.out) ]"
check "--example --thick: answers shown as the record echoes them" sh -c "
    cd '$S' && '$BIN' --thick --example th.rec > th.out &&
    grep '^input: ' th.rec | sed 's/^input: //' > th.ans && grep -cxFf th.ans th.out > /dev/null &&
    head -n 2 th.out | tail -n 1 | grep -qx cm"

escaped() (   # a subshell: its cd stays inside
    cd "$S" && printf '25\n1\n\033[31mabc\n' | "$BIN" e.rec > /dev/null 2> e.err; [ $? -eq 2 ] || return 1
    grep -qF "<stdin>:3: the radius of the lens surface: '\\x1b[31mabc' is not a number" e.err &&
        [ "$(tr -dc '\033' < e.err | wc -c)" -eq 0 ] || { cat -v e.err; return 1; }
    "$BIN" "--bad$(printf '\033')" x.rec 2> e2.err; [ $? -eq 1 ] && grep -qF "'--bad\\x1b'" e2.err || return 1
    printf 'nearpoint 25\n3 0 \033[31m1.5\n' | "$BIN" --prescription e3.rec 2> e3.err
    grep -qF '\x1b[31m1.5' e3.err && [ "$(tr -dc '\033' < e3.err | wc -c)" -eq 0 ]
)
check "messages escape control bytes (no raw ESC on the terminal)" escaped
check "a NUL byte in an answer line: FILE:LINE error, exit 2, answers before kept" sh -c "
    cd '$S' && printf '25\n1\n3\0003\n0\n' > nul.in && '$BIN' -i nul.in nul.rec > /dev/null 2> nul.err;
    [ \$? -eq 2 ] && grep -q '^lensmat: nul.in:3: this line holds a NUL byte' nul.err &&
    [ \$(grep -c '^input: ' nul.rec) -eq 2 ]"
check "answers left over on a later line: warned about with that line, exit 0" sh -c "
    cd '$S' && printf '25 1 3 0 1.5 n -10 n\n\n   \n99\n' | '$BIN' l.rec > /dev/null 2> l.err &&
    grep -q '^lensmat: <stdin>:4: warning: answers after the end of the dialogue were ignored' l.err"
check "no warning when only blank and comment lines follow" sh -c "
    cd '$S' && printf '25 1 3 0 1.5 n -10 n\n\n# done\n' | '$BIN' l2.rec > /dev/null 2> l2.err &&
    ! grep -q warning l2.err"

check "UTF-8 byte-order mark and # comment lines in a replay; line numbers stay right" sh -c "
    cd '$S' && { printf '\357\273\277# my lens\n'; cat '$CIN'; } > bom.in &&
    '$BIN' -i bom.in bom.rec > /dev/null && cmp bom.rec '$GOLDEN/cases/convex_thin_doc.rec' &&
    printf '\357\273\27725\n# the index\n  # and more\n1\nabc\n' > bom2.in &&
    ! '$BIN' -i bom2.in bom2.rec > /dev/null 2> bom2.err && grep -q '^lensmat: bom2.in:5: ' bom2.err"

# file names with blanks: quoted answers, echoed quoted, replayed
quoted_name() (   # a subshell: its cd stays inside
    cd "$S" || return 1
    "$BIN" "my lens.rec" < "$GOLDEN/cases/thick_r3_r4.in" > /dev/null || return 1
    printf 'record\n"my lens.rec"\n1\n10\n1\nn\nn\n' > q.in
    "$BIN" --trace -i q.in q.rec > q.out 2> q.err || { cat q.err; return 1; }
    grep -qx 'input: "my lens.rec"' q.rec || { grep input: q.rec; return 1; }
    grep -q 'Lens of 2 surfaces\|2 surfaces' q.rec || { cat q.rec | head; return 1; }
    grep input: q.rec > q2.in && "$BIN" --trace q2.rec < q2.in > /dev/null && cmp q.rec q2.rec || return 1
    # single quotes and escapes read the same name; a plain name is echoed as it is
    printf "record\n'my\\\\x20lens.rec'\n1\n10\n1\nn\nn\n" > q3.in
    "$BIN" --trace -i q3.in q3.rec > /dev/null && cmp q.rec q3.rec || return 1
    cp "my lens.rec" plain.rec
    printf 'record\nplain.rec\n1\n10\n1\nn\nn\n' > q4.in
    "$BIN" --trace -i q4.in q4.rec > /dev/null && grep -qx 'input: plain.rec' q4.rec || return 1
    printf 'record\n"my lens.rec\n' > q5.in
    "$BIN" --trace -i q5.in q5.rec > /dev/null 2> q5.err; [ $? -eq 2 ] &&
        grep -q 'q5.in:2: .*quote is not closed' q5.err
)
check "a quoted file name with a blank is an answer; echoed quoted; the replay works" quoted_name

# no output over an input: nothing truncated, whatever the spelling
same_file() (   # a subshell: its cd stays inside
    cd "$S" || return 1
    cp "$CIN" same.in; cp same.in keep
    "$BIN" -i same.in same.in > /dev/null 2> sf.err; [ $? -eq 1 ] || return 1
    grep -q 'same.in is the file the answers are read from' sf.err && cmp same.in keep || return 1
    "$BIN" ex.rec < "$CIN" > /dev/null && cp ex.rec self.rec && cp self.rec keep2
    "$BIN" self.rec < self.rec > /dev/null 2> sf2.err; [ $? -eq 1 ] && cmp self.rec keep2 || return 1
    rm -f hard.in; ln same.in hard.in
    "$BIN" -i same.in hard.in > /dev/null 2> /dev/null; [ $? -eq 1 ] && cmp same.in keep || return 1
    rm -f sym.in; ln -s "$S/same.in" sym.in
    "$BIN" sym.in < same.in > /dev/null 2> /dev/null; [ $? -eq 1 ] && cmp same.in keep || return 1
    "$BIN" ./same.in < "$S/../s17/same.in" > /dev/null 2> /dev/null; [ $? -eq 1 ] && cmp same.in keep
)
check "an output is never the input: -i same same, self < self, hard link, symlink, spelling" same_file

check "--input=F and -- are accepted" sh -c "
    cd '$S' && '$BIN' --input='$CIN' in1.rec > /dev/null && cmp in1.rec '$GOLDEN/cases/convex_thin_doc.rec' &&
    '$BIN' -- -dash.rec < '$CIN' > /dev/null && cmp ./-dash.rec in1.rec &&
    ! '$BIN' --input= x.rec < /dev/null 2> /dev/null"
check "-i missing: a lensmat: message, exit 1, no record made" sh -c "
    cd '$S' && '$BIN' -i missing.in m.rec > /dev/null 2> m.err; [ \$? -eq 1 ] &&
    grep -q \"^lensmat: cannot read the answers' file missing.in: No such file\" m.err && [ ! -e m.rec ]"
check "-i a folder: refused with a message, exit 1" sh -c "
    cd '$S' && '$BIN' -i '$S' d.rec > /dev/null 2> d.err; [ \$? -eq 1 ] && grep -q 'Is a directory' d.err && [ ! -e d.rec ]"
check "--original is refused where it means nothing, kept where it does" sh -c "
    cd '$S' && printf 'cm\n1\n3\n5\n1.4\n4\n1\nn\n' > th.in &&
    '$BIN' --thick --original -i th.in o.rec > /dev/null 2> o.err; [ \$? -eq 1 ] &&
    grep -q -- '--thick has no original' o.err && [ ! -e o.rec ] &&
    '$BIN' --original -i '$CIN' o2.rec > /dev/null &&
    '$BIN' --prescription --original --example o3.rec > /dev/null"

# a dialogue whose engine module is missing says so before its first question
missing_module() (   # a subshell: its cd stays inside
    mkdir -p "$S/alone" && cp "$BIN" "$S/alone/lensmat" && cd "$S/alone" || return 1
    printf 'cm\ncardinal\n' > f.in
    LENSMAT_LIBDIR=/nonexistent ./lensmat --fit -i f.in f.rec > f.out 2> f.err; [ $? -eq 1 ] || return 1
    grep -q 'fit engine (lensmat-fit.so) is not built or not installed' f.err &&
        grep -q -- '--fit needs the fit engine module' f.err || { cat f.err; return 1; }
    [ ! -s f.out ] && [ ! -e f.rec ] || return 1
    ./lensmat --trace --example t.rec > /dev/null 2> t.err; [ $? -eq 1 ] || return 1
    # LENSMAT_LIBDIR points to the modules
    LENSMAT_LIBDIR=$TOP/build/lib ./lensmat --trace --example t.rec > /dev/null
)
check "missing engine module: said before the first question, exit 1; LENSMAT_LIBDIR finds it" missing_module

# the same readers under ASan/UBSan
SAVED_BIN=$BIN; BIN=$ASAN
check "asan: escaped messages" escaped
check "asan: quoted file names" quoted_name
check "asan: no output over an input" same_file
BIN=$SAVED_BIN

# the table against --help and the man page; the quoted-word reader
unit "$TOP/build/obj/unit_dialogue"
unit "$TOP/build/asan/unit_dialogue"

# found by the dialogue fuzzer: a plane surface in --gauss printed focal points -inf, inf
check "--gauss, a surface without power: no inf printed" sh -c "
    cd '$S' && printf 'cm\n1\n3\n0\n1.4\nn\n' | '$BIN' --gauss g.rec > g.out &&
    grep -q 'no power: its focal points are at infinity' g.rec && ! grep -q '= -*inf' g.rec"
# found by the dialogue fuzzer: an afocal --thick lens ended the dialogue with the
# paraxial engine's code (no "Output was written", no leftover check)
check "--thick, an afocal lens: the dialogue ends normally" sh -c "
    cd '$S' && printf 'cm\n1\n0\n1\n1.5\n0\n1\n' | '$BIN' --thick af.rec > af.out &&
    grep -q afocal af.out && grep -q '^Output was written' af.out"
# found by the dialogue fuzzer: --thin printed an answer of inf as "di= inf"
check "--thin, a distance at infinity: said as infinity, no inf printed" sh -c "
    cd '$S' && printf 'cm\nf\n168\ninf\n-2\n' | '$BIN' --thin ti.rec > ti.out &&
    grep -q 'di= infinity' ti.rec && ! grep -q '= -*inf\\>' ti.rec"
check "a NUL byte in a prescription or lens file: FILE:LINE, not a silent cut" sh -c "
    cd '$S' && printf 'nearpoint 25\n3 0 1.5\n-3 0 1\000junk\nobject -2\n' > p.rx &&
    '$BIN' --prescription -i p.rx p.rec > /dev/null 2> p.err; [ \$? -eq 2 ] &&
    grep -q '^lensmat: p.rx:3: this line holds a NUL byte' p.err &&
    printf '25\n1\n3\n0\n1.5\n\000y\n' > c.in && printf 'record\nc.in\n' > r.in &&
    '$BIN' --trace -i r.in t.rec > /dev/null 2> t.err; [ \$? -eq 2 ] && grep -q 'c.in:6: this line holds a NUL' t.err"
check "lens and prescription files: BOM and # comment lines as in a replay" sh -c "
    cd '$S' && { printf '\357\273\277# my lens\n'; cat '$CIN'; } > lb.in &&
    '$BIN' --to-prescription -i lb.in lb.rx && '$BIN' --prescription -i lb.rx lb.rec > /dev/null &&
    cmp lb.rec '$GOLDEN/cases/convex_thin_doc.rec' &&
    { printf '\357\273\277'; cat lb.rx; } > lb2.rx && '$BIN' --prescription -i lb2.rx lb2.rec > /dev/null &&
    cmp lb.rec lb2.rec && printf 'record\nlb.in\n1\n10\n1\nn\nn\n' > lt.in &&
    { '$BIN' --trace -i lt.in lt.rec > /dev/null 2> lt.err; [ \$? -eq 2 ]; } &&
    grep -q 'lb.in: surfaces 1 and 2 touch on the axis' lt.err"
# (--trace reads the same file through its BOM and comment, and then refuses the
# document's thin lens: its two surfaces at z = 0 cross off the axis, issue 8.)
