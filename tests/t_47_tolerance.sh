# t_47_tolerance.sh -- tolerancing (src/design/ds_tol.c, tests/design/t_tolerance.c:
# sensitivities against the test's own y-nu trace, the Monte Carlo EFL spread against
# the linear prediction, the compensator's minimum) and the --tolerance dialogue with
# scripts/tolerance-mc.sh (GNU parallel jobs = one process, byte for byte).
unit "$TOP/build/obj/design_tests/t_tolerance"
unit "$TOP/build/asan/design_tests/t_tolerance"

tol_dir() { mkdir -p "$WORK/tl" && ln -sfn "$TOP/doc" "$WORK/tl/doc"; }

tol_example() (
    tol_dir && cd "$WORK/tl" && "$1" --tolerance --example t.rec > t.out || return 1
    grep -q '^  200 lenses (0 with a failed ray)' t.rec && grep -q '^  yield (RMS <= 25 um)' t.rec &&
    grep input: t.rec > t.in && "$1" --tolerance t2.rec < t.in > /dev/null && cmp t.rec t2.rec
)
check "--tolerance: example (Monte Carlo of 200 triplets): table summary, yield; replays" tol_example "$BIN"
check "--tolerance: the same under ASan/UBSan" tol_example "$ASAN"

# Sensitivities: one row per tolerance (6 radii, 5 thicknesses, 3 glasses); replay.
check "--tolerance: sensitivities of the triplet: 14 rows, a linear EFL prediction; replays" sh -c "
    cd '$WORK/tl' && printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian.tol\nsens\n' > s.in &&
    '$BIN' --tolerance -i s.in s.rec > /dev/null && [ \$(grep -c '^  [rtn] [1-6] ' s.rec) -eq 14 ] &&
    grep -q 'linear prediction: efl sd' s.rec &&
    grep input: s.rec > s2.in && '$BIN' --tolerance s2.rec < s2.in > /dev/null && cmp s.rec s2.rec"

# Many jobs under GNU parallel give the table of one process, byte for byte, and the
# same summary as the Monte Carlo dialogue's own.
tol_parallel() (
    cd "$WORK/tl" || return 1
    LENSMAT=$1 sh "$TOP/scripts/tolerance-mc.sh" -f doc/design/sasian-triplet.rx \
        -t doc/design/sasian.tol -N 600 -C 75 -s 42 -l 16 -j 2 -o par > par.out || return 1
    printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian.tol\nmc\n600\n1\n42\nuniform\nbfd\n16\none.tab\n' > one.in &&
    "$1" --tolerance -i one.in one.rec > /dev/null || return 1
    cmp par/table.txt one.tab || return 1
    [ "$(grep -c . one.tab)" -eq 601 ] || return 1
    grep -E '^  (.* lenses \(|RMS um|efl mean|yield)' one.rec > a.txt &&
    grep -E '^  (.* lenses \(|RMS um|efl mean|yield)' par/summary.rec > b.txt && cmp a.txt b.txt
)
check "tolerance-mc.sh: 8 jobs under GNU parallel = one process (table and summary byte-identical)" tol_parallel "$BIN"

# SIGTERM during a long Monte Carlo: exit 143, no table under its name, no temporary.
tol_term() (
    cd "$WORK/tl" && rm -f big.tab big.tab.tmp.* &&
    printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian.tol\nmc\n1000000\n1\n1\nuniform\nbfd\n0\nbig.tab\n' > big.in &&
    { "$1" --tolerance -i big.in big.rec > big.out 2> big.err & pid=$!; } &&
    sleep 3; kill -TERM $pid; wait $pid; rc=$?
    [ $rc -eq 143 ] && grep -q 'Stopped by a signal' big.out && [ ! -e big.tab ] &&
        ! ls big.tab.tmp.* 2> /dev/null
)
check "--tolerance: SIGTERM mid-Monte-Carlo stops, says so, exit 143, writes nothing" tol_term "$BIN"

check "--tolerance: a bad table row is refused with FILE:LINE" sh -c "
    cd '$WORK/tl' && printf '# lens rms_um efl bfd focus\n1 15.2 50 41 0\nbroken row\n' > bad.tab &&
    printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian.tol\ntable\nbad.tab\n0\n' > bt.in
    '$BIN' --tolerance -i bt.in bt.rec > /dev/null 2> bt.err; rc=\$?
    [ \$rc -eq 2 ] && grep -q 'bad.tab:3: not a row of a tolerance table' bt.err"
check "--tolerance: an unknown tolerance kind (tilt: tx ty dx dy are the kinds) is refused with FILE:LINE" sh -c "
    cd '$WORK/tl' && printf 'tol tilt 1 0.1\n' > tilt.tol &&
    printf 'doc/design/sasian-triplet.rx\ntilt.tol\n' > tt.in
    '$BIN' --tolerance -i tt.in tt.rec > /dev/null 2> tt.err; rc=\$?
    [ \$rc -eq 2 ] && grep -q \"tilt.tol:1: 'tilt' is not a tolerance\" tt.err"
