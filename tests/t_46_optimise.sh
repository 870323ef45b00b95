# t_46_optimise.sh -- damped least squares (src/design, tests/design/t_optimise.c:
# closed forms: a singlet's bending, an achromat; quadrature spots) and the --optimise
# dialogue: Sasian's triplet recovered from radii perturbed by 10 %, replay, outputs
# that never overwrite an input, FILE:LINE refusals, SIGTERM mid-run.
unit "$TOP/build/obj/design_tests/t_optimise"
unit "$TOP/build/asan/design_tests/t_optimise"

opt_dir() { mkdir -p "$WORK/op" && ln -sfn "$TOP/doc" "$WORK/op/doc"; }

# The example: from doc/design/sasian-start.rx (radii x1.1, x0.9 alternately) to a
# merit at most the published design's under the same merit function, and every
# field's RMS spot at most the published design's (the published values: the
# operands of a run that starts from doc/design/sasian-triplet.rx).
opt_example() (
    opt_dir && cd "$WORK/op" && rm -f sasian-optimised.rx &&
    "$1" --optimise --example o.rec > o.out || return 1
    grep -q 'method: GSL multifit_nlinear: Levenberg-Marquardt' o.rec || return 1
    grep -q '^Wrote the optimised prescription to sasian-optimised.rx' o.rec || return 1
    printf 'doc/design/sasian-triplet.rx\n-\n1\npub-out.rx\n' > pub.in &&
    "$1" --optimise -i pub.in pub.rec > /dev/null || return 1
    # start merit of the published lens vs end merit of the optimised one
    pm=$(awk '/^  iteration   0/ { print $4; exit }' pub.rec)
    om=$(awk '/^Merit / { print $4 }' o.rec)
    awk -v a="$om" -v b="$pm" 'BEGIN { exit !(a <= b) }' || { echo "merit $om > published $pm"; return 1; }
    for f in 1 2 3; do
        p=$(awk -v f="$f" '/operands \(target/ { on = 1 } /^  iteration/ { on = 0 }
                on && $1 == "rms" && $3 == f { print $6; exit }' pub.rec)
        o=$(awk -v f="$f" '/operands at the end/ { on = 1 }
                on && $1 == "rms" && $3 == f { print $6; exit }' o.rec)
        awk -v a="$o" -v b="$p" 'BEGIN { exit !(a <= b && a > 0) }' ||
            { echo "field $f: RMS $o > published $p"; return 1; }
    done
    # the written prescription reads back with the same merit (one more run: its start)
    printf 'sasian-optimised.rx\n-\n1\nagain.rx\n' > again.in &&
    "$1" --optimise -i again.in again.rec > /dev/null || return 1
    am=$(awk '/^  iteration   0/ { print $4; exit }' again.rec)
    awk -v a="$am" -v b="$om" 'BEGIN { exit !(a <= b * (1 + 1e-6)) }' ||
        { echo "re-read merit $am, written $om"; return 1; }
    # replay: the grep'd record gives the same record (seconds are on stdout only)
    grep input: o.rec > o.in && rm -f sasian-optimised.rx &&
    "$1" --optimise o2.rec < o.in > /dev/null && cmp o.rec o2.rec || return 1
    # not an artefact of 9 rays a field: with 16 rings x 32 arms (the spots converged
    # to 1e-5) every field of the optimised lens still beats the published one's
    printf 'vary t 6\ntarget rms 0\ndesign rings 16 arms 32\n' > dense.mf
    for l in sasian-optimised doc/design/sasian-triplet; do
        sed '/^vary\|^target\|^min\|^design/d' $l.rx > dense-in.rx &&
        printf 'dense-in.rx\ndense.mf\n1\ndense-out.rx\n' > dense.in &&
        "$1" --optimise -i dense.in dense.rec > /dev/null || return 1
        awk '/operands \(target/ { on = 1 } /^  iteration/ { on = 0 } on && $1 == "rms" { print $6 }' dense.rec > "$(basename $l).dense"
    done
    paste sasian-optimised.dense sasian-triplet.dense | awk '{ n++; if (!($1 < $2)) bad = 1 } END { exit bad || n != 3 }'
)
check "--optimise: triplet from radii perturbed 10 %: merit and every field's RMS <= the published design's; replays" opt_example "$BIN"
check "--optimise: the same under ASan/UBSan" opt_example "$ASAN"

# From flat-ish surfaces (radii +-200 or plane) in two stages: first and third order
# (doc/design/sasian-stage1.mf: efl, Seidel SI-SIII, axial and lateral colour to 0,
# which the test checks in the record), then the real-ray merit: the same merit and
# per-field RMS limits as above (pub.rec from opt_example).
opt_flat() (
    cd "$WORK/op" && rm -f s1.rx s2.rx &&
    printf 'doc/design/sasian-flat.rx\ndoc/design/sasian-stage1.mf\n300\ns1.rx\n' > s1.in &&
    "$1" --optimise -i s1.in s1.rec > /dev/null || return 1
    awk '/operands at the end/ { on = 1 }
         on && ($1 == "spha" || $1 == "coma" || $1 == "asti" || $1 == "axcl" || $1 == "lacl") {
             v = $4 < 0 ? -$4 : $4; if (v > 1e-9) bad = 1; n++ }
         on && $1 == "efl" { e = $4 - 50; if (e < 0) e = -e; if (e > 1e-9) bad = 1 }
         END { exit bad || n != 5 }' s1.rec || { echo "stage 1 not solved"; return 1; }
    printf 's1.rx\ndoc/design/sasian-stage2.mf\n300\ns2.rx\n' > s2.in &&
    "$1" --optimise -i s2.in s2.rec > /dev/null || return 1
    pm=$(awk '/^  iteration   0/ { print $4; exit }' pub.rec)
    om=$(awk '/^Merit / { print $4 }' s2.rec)
    awk -v a="$om" -v b="$pm" 'BEGIN { exit !(a <= b) }' || { echo "merit $om > published $pm"; return 1; }
    for f in 1 2 3; do
        p=$(awk -v f="$f" '/operands \(target/ { on = 1 } /^  iteration/ { on = 0 }
                on && $1 == "rms" && $3 == f { print $6; exit }' pub.rec)
        o=$(awk -v f="$f" '/operands at the end/ { on = 1 }
                on && $1 == "rms" && $3 == f { print $6; exit }' s2.rec)
        awk -v a="$o" -v b="$p" 'BEGIN { exit !(a <= b && a > 0) }' ||
            { echo "field $f: RMS $o > published $p"; return 1; }
    done
)
check "--optimise: from flat-ish surfaces in two stages (Seidel, then real rays): <= the published design" opt_flat "$BIN"

# The output never overwrites an input; refused at its answer, exit 2, input intact.
check "--optimise: output = the lens file is refused, the file untouched" sh -c "
    cd '$WORK/op' && cp doc/design/sasian-start.rx mine.rx && cp mine.rx keep.rx &&
    printf 'mine.rx\n-\n5\nmine.rx\n' > ow.in
    '$BIN' --optimise -i ow.in ow.rec > /dev/null 2> ow.err; rc=\$?
    [ \$rc -eq 2 ] && grep -q 'ow.in:4: .*mine.rx is an input' ow.err && cmp mine.rx keep.rx"

# Bad lines name FILE:LINE: in a merit file, and in the lens file itself.
check "--optimise: a bad merit line is refused with FILE:LINE" sh -c "
    cd '$WORK/op' && printf '# a merit file\ntarget efl fifty\n' > bad.mf &&
    printf 'doc/design/sasian-start.rx\nbad.mf\n' > bm.in
    '$BIN' --optimise -i bm.in bm.rec > /dev/null 2> bm.err; rc=\$?
    [ \$rc -eq 2 ] && grep -q \"bad.mf:2: 'fifty' is not a number\" bm.err"
check "--optimise: a bad vary line in the lens file is refused with FILE:LINE" sh -c "
    cd '$WORK/op' && sed 's/^vary t 6/vary t 60/' doc/design/sasian-start.rx > badv.rx &&
    printf 'badv.rx\n' > bv.in
    '$BIN' --optimise -i bv.in bv.rec > /dev/null 2> bv.err; rc=\$?
    [ \$rc -eq 2 ] && grep -q \"badv.rx:27: '60': give a surface number from 1 to 6\" bv.err"

# SIGTERM mid-optimisation: stops promptly, says so, exit 143, nothing written (no
# output, no temporary).  A slow merit (32 rings x 42 arms: some 10 s of iterations on
# one core), signalled once the run has used half a second of CPU (by the process's
# own clock, /proc/PID/stat, so a loaded machine cannot make it finish first).
opt_term() (
    cd "$WORK/op" && rm -f slow-out.rx slow-out.rx.tmp.* slow-out.rx.part.* &&
    { cat doc/design/sasian-start.rx; echo 'design rings 32 arms 42'; } > slow.rx &&
    printf 'slow.rx\n-\n10000\nslow-out.rx\n' > slow.in &&
    { "$1" --optimise -i slow.in slow.rec > slow.out 2> slow.err & pid=$!; } &&
    i=0; while [ "$(awk '{ print $14 + $15 }' /proc/$pid/stat 2> /dev/null || echo 0)" -lt 50 ]; do
        kill -0 $pid 2> /dev/null || break
        i=$((i + 1)); [ $i -gt 6000 ] && break; sleep 0.01; done
    kill -TERM $pid; wait $pid; rc=$?
    [ $rc -eq 143 ] && grep -q 'Stopped by a signal' slow.out && grep -q 'stopped' slow.err &&
        [ ! -e slow-out.rx ] && ! ls slow-out.rx.tmp.* slow-out.rx.part.* 2> /dev/null
)
check "--optimise: SIGTERM mid-run stops, says so, exit 143, writes nothing" opt_term "$BIN"

check "--optimise and --tolerance are in --help and the man page" sh -c "
    '$BIN' --help | grep -q -- '--optimise' && '$BIN' --help | grep -q -- '--tolerance' &&
    grep -q 'optimise' '$TOP/doc/lensmat.1' && grep -q 'tolerance' '$TOP/doc/lensmat.1'"

# The distortion operand against --pupil's own chief-ray distortion (src/dialogue/
# pupil.c: its own aiming request and paraxial image height) for Sasian's triplet at
# 14.14 and 20 degrees, d: the same 4 digits.
check "--optimise: dist operand = --pupil's real chief-ray distortion (triplet, 2 fields)" sh -c "
    cd '$WORK/op' && sed '/^vary\|^target\|^min/d' doc/design/sasian-triplet.rx > plain.rx &&
    printf 'plain.rx\nhex\n4\nn\n' > pp.in && '$BIN' --pupil -i pp.in pp.rec > /dev/null &&
    { cat plain.rx; printf 'vary t 6\ntarget dist 0 field 2\ntarget dist 0 field 3\n'; } > dd.rx &&
    printf 'dd.rx\n-\n1\ndd-out.rx\n' > dd.in && '$BIN' --optimise -i dd.in dd.rec > /dev/null &&
    a=\$(awk '/^Wavelength 587/ { on = 1 } /^Wavelength 486/ { on = 0 } on && /distortion -?[0-9]/ { sub(/.*distortion /, \"\"); sub(/ %.*/, \"\"); printf \"%.4g \", \$0 }' pp.rec | cut -d' ' -f1-2) &&
    b=\$(awk '/operands \\(target/ { on = 1 } /^  iteration/ { on = 0 } on && \$1 == \"dist\" { printf \"%.4g \", \$6 }' dd.rec | sed 's/ \$//') &&
    [ -n \"\$a\" ] && [ \"\$a\" = \"\$b\" ] || { echo \"pupil '\$a' design '\$b'\"; exit 1; }"
