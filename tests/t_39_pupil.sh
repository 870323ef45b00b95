# t_39_pupil.sh -- first-order pupils (src/paraxial/pupil.c, tests/unit_pupil.c),
# real rays aimed at the stop (src/trace/tr_aim.c, tests/trace/t_aim.c), and the
# --pupil dialogue: pupil data, chief rays, spots and fans per field and wavelength.
unit "$TOP/build/obj/unit_pupil"
unit "$TOP/build/asan/unit_pupil"
unit "$TOP/build/obj/trace_tests/t_aim"
unit "$TOP/build/asan/trace_tests/t_aim"

# --pupil: the embedded example (doc/pupil-triplet.rx: the Zemax tutorial's Cooke
# triplet, EPD 10, fields 0 14 20 degrees, d F C), run in a folder that links doc/.
pupil_dir() { mkdir -p "$WORK/pu" && ln -sfn "$TOP/doc" "$WORK/pu/doc"; }
pupil_example() (   # a subshell: its cd stays inside
    pupil_dir && cd "$WORK/pu" && "$1" --pupil --example p.rec > p.out || return 1
    # first-order data at d: efl, pupils, the stop's size (y-nu trace, pupil.c)
    grep -q '^  efl 50.0213, f-number 5.002, working f-number 5.002' p.rec || return 1
    grep -q '^  entrance pupil z= 11.5056, diameter 10; exit pupil z= 9.22129, diameter 10.2324; stop semi-diameter 3.80455' p.rec || return 1
    # the chief ray's paraxial height at 14 degrees is efl tan(14 deg) = 12.4717
    grep -q 'paraxial image height 12.4717 ' p.rec || return 1
    # the vignetting of the 20-degree field by surface 1 (semi-diameter 8)
    grep -q 'spot: 98 rays, 14 vignetted' p.rec || return 1
    # replay: the grep'd record gives the same record
    grep input: p.rec > p.in && "$1" --pupil p2.rec < p.in > /dev/null && cmp p.rec p2.rec
)
check "--pupil: example (triplet): efl, pupils, f-number, vignetting; replays exactly" pupil_example "$BIN"
check "--pupil: the same under ASan/UBSan" pupil_example "$ASAN"

# Every chief ray of the example (3 fields x 3 wavelengths) crosses the stop within
# 1e-9 mm of its centre, and every ray of every spot within 1e-9 mm of its target.
check "--pupil: chief rays hit the stop centre to 1e-9 mm, all aimed rays to 1e-9" sh -c "
    cd '$WORK/pu' && n=\$(grep -c 'stop miss' p.rec) && [ \"\$n\" -eq 9 ] &&
    awk '/stop miss/ { for (i = 1; i <= NF; i++) if (\$i == \"miss\") m = \$(i + 1);
                       if (m + 0 > 1e-9) bad = 1 }
         /stop residual at most/ { for (i = 1; i <= NF; i++) if (\$i == \"most\") m = \$(i + 1);
                       if (m + 0 > 1e-9) bad = 1 }
         END { exit bad }' p.rec"
# On axis the spot is symmetric: its centroid is the chief ray's point (RMS equal).
check "--pupil: on-axis spot: RMS about the chief ray = about the centroid" sh -c "
    cd '$WORK/pu' && grep -A1 'field 1: 0 degrees' p.rec > /dev/null &&
    awk '/field 1: 0 degrees/ { on = 1 } /field 2:/ { on = 0 }
         on && /RMS radius/ { split(\$0, a, \"chief ray \"); split(a[2], b, \",\");
                              split(\$0, c, \"centroid \"); split(c[2], e, \";\");
                              n++; if (b[1] != e[1]) bad = 1 }
         END { exit bad || n != 3 }' p.rec"

# A plano-convex lens of index 1.5, R 50 (f = R/(n-1) = 100), stop 20 mm in front,
# EPD 10: f/10, the entrance pupil is the stop (z = 0), and the exit pupil is the
# stop's image by the lens: the stop lies 20 before H1 (the convex vertex, z = 20),
# so 1/s' = 1/100 - 1/20, s' = -25 from H2, which lies t (n-1)/n = 5/3 right of H1:
# z = 20 + 5/3 - 25 = -3.33333, diameter 10 * 25/20 = 12.5.
pupil_pc() (   # a subshell: its cd stays inside
    pupil_dir && cd "$WORK/pu" && printf '%s\n' thickness 'epd 10' 'field angle 0 5' \
        'plane 20 air stop' '50 5 1.5' 'plane 0 air' > pc.rx &&
    printf 'pc.rx\ngrid\n4\nn\n' > pc.in && "$1" --pupil -i pc.in pc.rec > /dev/null &&
    grep -q '^  efl 100, f-number 10, ' pc.rec &&
    grep -q '^  entrance pupil z= 0, diameter 10; exit pupil z= -3.33333, diameter 12.5; stop semi-diameter 5 ' pc.rec
)
check "--pupil: plano-convex behind a stop: f/10, EP = stop, XP at its image" pupil_pc "$BIN"

# A file without stop, aperture or fields (the classic positions format of
# doc/triplet.rx, object at z = -1000): they are asked, and echoed in the record.
check "--pupil: what the file lacks is asked (stop, aperture, object heights)" sh -c "
    cd '$WORK/pu' && printf 'doc/triplet.rx\n4\nepd\n10\n2\n0\n300\nhex\n4\nn\n' > t.in &&
    '$BIN' --pupil -i t.in t.rec > /dev/null &&
    grep -q 'stop at surface 4, EPD 10, object 1000 mm left of surface 1, 2 fields' t.rec &&
    grep -q 'field 2: object height 300' t.rec && grep -q 'spot: 61 rays, 0 vignetted' t.rec &&
    grep input: t.rec > t2.in && '$BIN' --pupil t2.rec < t2.in > /dev/null && cmp t.rec t2.rec"

# Refusals: FILE:LINE and exit 2 in a replay; the record keeps the answers accepted.
pupil_refuse() {  # NAME ANSWERS MESSAGE [FILE-LINES...]
    name=$1 ans=$2 msg=$3; shift 3
    check "$name" sh -c "
        cd '$WORK/pu' && { [ \$# -eq 0 ] || printf '%s\n' \"\$@\" > bad.rx; } &&
        printf '$ans' > bad.in; '$ASAN' --pupil -i bad.in bad.rec > /dev/null 2> bad.err
        rc=\$?; [ \$rc -eq 2 ] && grep -qF -- \"$msg\" bad.err" sh "$@"
}
pupil_refuse "--pupil: a missing file is refused at its answer" 'nosuch.rx\n' \
    "bad.in:1: the lens file: nosuch.rx: cannot be read"
pupil_refuse "--pupil: stop 9 of 6 surfaces refused" 'doc/triplet.rx\n9\n' \
    "'9': give a surface number from 1 to 6"
pupil_refuse "--pupil: field angle 95 refused" 'bad.rx\n3\n95\n' \
    "strictly between -90 and 90" thickness 'epd 10' 'index air' '50 5 1.5 stop' 'plane 0 air'
pupil_refuse "--pupil: a virtual object (right of surface 1) is refused at the file" \
    'bad.rx\n' "a virtual object" thickness 'epd 10' 'field height 0 1' 'object 20' \
    '50 5 1.5 stop' 'plane 0 air'
pupil_refuse "--pupil: an afocal lens is refused with the reason" 'bad.rx\ngrid\n4\nn\n' \
    "afocal" thickness 'epd 10' 'field angle 0 1' '50 0 1.5 stop' '-50 75 air' \
    '25 0 1.5' '-25 0 air'
pupil_refuse "--pupil: stop in the back focal plane, object at infinity: refused" \
    'bad.rx\ngrid\n4\nn\n' "focal plane" thickness 'epd 10' 'field angle 0 1' \
    '50 0 1.5' '-50 50 air' 'plane 0 air stop'

# A Zemax file (tests/zmx/AC254-100-A.zmx, Thorlabs' achromat: ENPD 22.86, stop at
# surface 1, WAVL F d C): its pupils and focal length (Thorlabs: f 100.1 mm).
check "--pupil: a .zmx (Thorlabs AC254-100-A): EPD from ENPD, efl 100.07, EP at the stop" sh -c "
    cd '$WORK/pu' && ln -sfn '$TOP/tests' tests && printf 'tests/zmx/AC254-100-A.zmx\nhex\n3\nn\n' > z.in &&
    '$BIN' --pupil -i z.in z.rec > /dev/null &&
    grep -q 'stop at surface 1, EPD 22.86, object at infinity' z.rec &&
    grep -q '^  efl 100.07, f-number 4.378' z.rec &&
    grep -q '^  entrance pupil z= 0, diameter 22.86; ' z.rec &&
    grep -q 'spot: 37 rays, 0 vignetted' z.rec"

# Object-space telecentric: the stop in the back focal plane of a convex-plane lens
# (f = 100, H2 at its convex vertex) with a finite object, aperture by NA: the
# entrance pupil is at infinity (printed as a word, no f-number), the chief ray of
# the 2 mm field is parallel to the axis in object space and is still aimed.
check "--pupil: object-space telecentric: EP at infinity, no f-number, chief ray aimed" sh -c "
    cd '$WORK/pu' && printf '%s\n' thickness 'na 0.05' 'field height 0 2' 'object -200' \
        'plane 4 1.5' '-50 100 air' 'plane 0 air stop' > tc.rx &&
    printf 'tc.rx\nhex\n3\nn\n' > tc.in && '$ASAN' --pupil -i tc.in tc.rec > /dev/null &&
    grep -q '^  efl 100, f-number -, ' tc.rec &&
    grep -q '^  entrance pupil z= infinity, diameter infinity; exit pupil z= 104, diameter 10;' tc.rec &&
    grep -q '^    object             -         0.05            -            0 ' tc.rec &&
    [ \$(grep -c 'spot: 37 rays, 0 vignetted' tc.rec) -eq 2 ] && ! grep -qw 'inf\|nan' tc.rec"

# Fields off the meridional plane: the triplet is round, so a field of 14 degrees in
# x gives the 14-degree y field's image height and spot turned by 90 degrees (the
# grid is symmetric about the diagonal), and 10 degrees in x and in y, whose
# direction is 14.0 degrees off the axis, has the same distortion to 4 digits.
check "--pupil: x fields: rotated image height and spot, the same distortion" sh -c "
    cd '$WORK/pu' && sed 's/^field angle 0 14 20/field angle 14,0 0,14 10,10/' doc/pupil-triplet.rx > xy.rx &&
    printf 'xy.rx\ngrid\n12\nn\n' > xy.in && '$BIN' --pupil -i xy.in xy.rec > /dev/null &&
    grep -q 'real (12.4195, 0) (distortion 0.02805 %)' xy.rec &&
    grep -q 'real 12.4195 (distortion 0.02805 %)' xy.rec &&
    [ \$(grep -c 'RMS radius about the chief ray 0.0154774, about the centroid 0.0154311;' xy.rec) -ge 2 ] &&
    grep -q 'real (8.78319, 8.78319) (distortion 0.02805 %)' xy.rec"

# On a terminal: a missing file, a stop out of range, a bad sampling word and a count
# too large are explained and asked again; the record keeps only accepted answers.
if python3 -c 'import pty' 2>/dev/null; then
    mkdir -p "$WORK/pu_tty"
    check "--pupil on a tty: bad answers explained and asked again" \
        python3 "$TOP/tests/tty_pupil.py" "$BIN" "$TOP" "$WORK/pu_tty"
fi

# SIGINT while many rays are aimed (16 fields x 8 wavelengths x 3169 spot rays and
# two 101-ray fans, several seconds): exit 130 within a second, no further output.
pupil_sigint() {
    d=$WORK/pu_sig; rm -rf "$d"; mkdir -p "$d"
    sed 's/^field angle 0 14 20/field angle 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15/;
         s/^wavelengths d F C/wavelengths d F C e g 500 600 700/' "$TOP/doc/pupil-triplet.rx" > "$d/big.rx"
    printf 'big.rx\nhex\n32\ny\n101\n' > "$d/in"
    (cd "$d" && exec "$BIN" --pupil -i in r.rec > out 2> err) &
    pid=$!
    sleep 0.5
    kill -INT "$pid"
    t0=$(date +%s%N)
    wait "$pid"; rc=$?
    t1=$(date +%s%N)
    [ "$rc" -eq 130 ] || { echo "exit $rc"; return 1; }
    [ $(( (t1 - t0) / 1000000 )) -lt 1000 ] || { echo "took $(( (t1 - t0) / 1000000 )) ms"; return 1; }
    ! grep -q 'Output was written' "$d/out"
}
check "--pupil: SIGINT while aiming exits 130 at once" pupil_sigint

# The wave aberration W (waves, Welford's sign) against the ray aberration on axis:
# ey = -(R / (n' r_xp)) dW/dpy lambda (R the reference sphere's radius, r_xp the exit
# pupil's semi-diameter, py the pupil coordinate): from a 101-ray fan at d, the
# central difference of W at py = 0.3, 0.5, 0.7, 0.9 predicts ey to 2 % of the fan's
# largest ey (the relation is first order in the pupil's own aberration: measured
# 0.4 % at 0.3, 1.1 % at 0.5, 1.6 % at 0.7 of the largest).
check "--pupil: wave aberration W agrees with the ray fan (ey = -R/(n' r_xp) dW/dpy)" sh -c "
    cd '$WORK/pu' && printf 'doc/pupil-triplet.rx\nhex\n4\ny\n101\n' > w.in &&
    '$BIN' --pupil -i w.in w.rec > /dev/null &&
    awk '/^Wavelength/ { nwl++ } nwl == 1 && /field 1:/ { on = 1 } nwl == 1 && /field 2:/ { on = 0 }
         on && /reference sphere radius/ { s = \$0; sub(/.*radius /, \"\", s); R = s + 0;
                  s = \$0; sub(/.*semi-diameter /, \"\", s); sub(/\\).*/, \"\", s); r = s + 0 }
         on && NF == 4 && \$1 ~ /^-?[0-9.]+\$/ { p = sprintf(\"%.2f\", \$1); ey[p] = \$2; W[p] = \$3
                  m = \$2 < 0 ? -\$2 : \$2; if (m > big) big = m }
         END { lam = 587.5618e-6; n = 0
               split(\"0.30 0.50 0.70 0.90\", at, \" \")
               for (i = 1; i <= 4; i++) {
                   a = sprintf(\"%.2f\", at[i] - 0.02); b = sprintf(\"%.2f\", at[i] + 0.02)
                   pred = -(R / r) * (W[b] - W[a]) / 0.04 * lam
                   if (ey[at[i]] == \"\" || R == 0) exit 1
                   rel = (pred - ey[at[i]]) / big; if (rel < 0) rel = -rel
                   printf \"py %s: ey %s, from W %.6g (%.2g)\n\", at[i], ey[at[i]], pred, rel
                   if (rel > 0.02) bad = 1; n++ }
               exit bad || n != 4 }' w.rec"

# Off axis the paths start on the incoming plane wavefront, not on the plane z = 0:
# counted from z = 0 the 14- and 20-degree fields would show a tilt of n y sin(field),
# thousands of waves over the 10 mm pupil; the example's RMS W stays under 1 wave in
# all 9 fields and wavelengths.
check "--pupil: wavefront: RMS W under 1 wave for every field (no tilt from the start plane)" sh -c "
    cd '$WORK/pu' && [ \$(grep -c 'RMS .* waves' p.rec) -eq 9 ] &&
    awk '/RMS .* waves/ { if (\$2 + 0 >= 1 || \$2 + 0 <= 0) bad = 1 } END { exit bad }' p.rec"
