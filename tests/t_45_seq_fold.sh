# t_45_seq_fold.sh -- folded and tilted systems in the sequential trace: real rays
# reflected at mirrors and carried through coordinate breaks (src/trace/tr_aim.c,
# tests/trace/t_seqfold.c: closed forms for mirrors, a Cassegrain, a fold, a
# decentred lens, a tilted plate, a break and its inverse), and --pupil on folded
# lenses (first order from the lens unfolded, real rays folded): a concave sphere's
# wavefront error against y^4 / (4 |R|^3), a parabola and a classical Cassegrain
# imaging the axis point perfectly (a spherical one not), the efl and image plane of
# the Cassegrain against the mirror equation, a flat fold against the lens unfolded.
unit "$TOP/build/obj/trace_tests/t_seqfold"
unit "$TOP/build/asan/trace_tests/t_seqfold"
SF=$WORK/sf
mkdir -p "$SF"
ZV=$TOP/tests/zmx-vendor

sf_pupil() {  # BIN LENS REC [RINGS]: --pupil, hexapolar, no fans
    printf '%s\nhex\n%s\nn\n' "$2" "${4:-4}" > "$SF/$3.in"
    (cd "$SF" && "$1" --pupil -i "$3.in" "$3.rec" > "$3.out" 2> "$3.err")
}

# A concave sphere R -200, EPD 25.4 (mirror-concave.zmx): the image at -100 (the file's
# DISZ), efl 100, and the wavefront's peak to valley at the paraxial focus is the
# mirror's Seidel term 2 x (sphere - paraboloid sag) = y^4 / (4 |R|^3) (0.5 %: the
# fifth-order part); replayed exactly.
sf_concave() {
    sf_pupil "$1" "$ZV/mirror-concave.zmx" cm || { cat "$SF/cm.err"; return 1; }
    grep -q '^Image plane z= -100 mm' "$SF/cm.rec" && grep -q '^  efl 100, ' "$SF/cm.rec" || return 1
    awk '/^Wavelength 587.562/ { on = 1 } on && /peak to valley/ {
            for (i = 1; i <= NF; i++) if ($i == "valley") pv = $(i + 1)
            w = 12.7 ^ 4 / (4 * 200 ^ 3) / 587.5618e-6
            printf "P-V %s waves, closed form %.6g\n", pv, w
            exit !(pv > 0 && (pv - w) / w < 0.005 && (w - pv) / w < 0.005) }' "$SF/cm.rec" || return 1
    (cd "$SF" && grep input: cm.rec > cm2.in && "$1" --pupil cm2.rec < cm2.in > /dev/null &&
        cmp cm.rec cm2.rec)
}
check "--pupil, concave sphere: image at -100, efl 100, W p-v = y^4/(4|R|^3) to 0.5 %, replays" sf_concave "$BIN"
check "--pupil, concave sphere: the same under ASan/UBSan" sf_concave "$ASAN"

# A classical Cassegrain: primary R -400 (f1 200, k -1), secondary 150 in front, the
# focus 250 behind it: 1/(-50) + 1/250 = 2/R2 gives R2 -125, m 5, efl f1 m = 1000,
# k2 = -((m + 1)/(m - 1))^2 = -2.25; exit pupil: the primary imaged by the secondary,
# 44.118 behind it (z -194.118).  The on-axis spot is a point; with spheres it is not.
cat > "$SF/cass.rx" <<'RX'
thickness
title Classical Cassegrain f/10
unit mm
wavelengths d
epd 100
field angle 0
index air
-400  -150  air  conic -1     mirror  stop
-125   250  air  conic -2.25  mirror
RX
sed -e 's/conic -1 /conic 0  /' -e 's/conic -2.25/conic 0    /' "$SF/cass.rx" > "$SF/cass-sph.rx"
sf_cass() {
    sf_pupil "$1" "$SF/cass.rx" ca || { cat "$SF/ca.err"; return 1; }
    grep -q '^Mirrors: 2; ' "$SF/ca.rec" &&
    grep -q '^  efl 1000, f-number 10, ' "$SF/ca.rec" &&
    grep -q '^  paraxial image z= 100,' "$SF/ca.rec" &&
    grep -q 'exit pupil z= -194.118, diameter 29.4118' "$SF/ca.rec" &&
    grep -q 'spot: 61 rays, 0 vignetted; RMS radius about the chief ray 0, about the centroid 0;' "$SF/ca.rec" &&
    grep -q 'RMS 0 waves, peak to valley 0 waves' "$SF/ca.rec" || return 1
    sf_pupil "$1" "$SF/cass-sph.rx" cs || return 1
    awk '/RMS radius about the chief ray/ { split($0, a, "chief ray "); split(a[2], b, ",")
         exit !(b[1] + 0 > 1e-3) }' "$SF/cs.rec"
}
check "--pupil, classical Cassegrain: efl 1000, image z 100, exit pupil, RMS spot 0 (spherical: not)" sf_cass "$BIN"

# A flat fold (singlet-fold.zmx: the singlet, 30 mm to the fold, -18 to the image)
# against the same file without the fold and 48 mm to the image: the same spot and
# wavefront, line for line.
awk 'BEGIN { RS = "\r\n"; ORS = "\r\n" }
     /^SURF 3/ { skip = 1 } /^SURF 4/ { skip = 0 }
     skip { next }
     /^SURF 4/ { $0 = "SURF 3" }
     /^SURF 2/ { s2 = 1 } s2 && /^  DISZ/ { $0 = "  DISZ 4.8E+1"; s2 = 0 }
     { print }' "$ZV/singlet-fold.zmx" > "$SF/unfold.zmx"
sf_fold() {
    sf_pupil "$1" "$ZV/singlet-fold.zmx" fo 6 || { cat "$SF/fo.err"; return 1; }
    sf_pupil "$1" "$SF/unfold.zmx" un 6 || { cat "$SF/un.err"; return 1; }
    grep -q '^Image plane z= 18 mm' "$SF/fo.rec" && grep -q '^Image plane z= 54 mm' "$SF/un.rec" &&
    grep -E 'spot:|RMS radius|centroid x|RMS .* waves|chief ray:' "$SF/fo.rec" > "$SF/fo.k" &&
    grep -E 'spot:|RMS radius|centroid x|RMS .* waves|chief ray:' "$SF/un.rec" > "$SF/un.k" &&
    [ -s "$SF/fo.k" ] && cmp "$SF/fo.k" "$SF/un.k"
}
check "--pupil, flat fold: spots and wavefronts as the lens unfolded (3 wavelengths)" sf_fold "$BIN"

# Coordinate breaks.  A 45-degree fold as OpticStudio writes one (fold-coordbrk.zmx
# with the break's twin after the mirror and the thickness after it negative, made
# here by awk): break (tilt 45 about x), the flat mirror, break (tilt 45), -18 to the
# image.  The image is the one the fold at normal incidence gives (singlet-fold.zmx).
awk 'BEGIN { RS = "\r\n"; ORS = "\r\n" }
     /^SURF 4/ { m = 1 } m && /^  DISZ/ { $0 = "  DISZ 0" }
     /^SURF 5/ { m = 0
                 print "SURF 5"; print "  TYPE COORDBRK"; print "  CURV 0.0 0 0 0 0 \"\""
                 print "  PARM 1 0"; print "  PARM 2 0"; print "  PARM 3 4.5E+1"
                 print "  PARM 4 0"; print "  PARM 5 0"; print "  PARM 6 0"
                 print "  DISZ -1.8E+1"; $0 = "SURF 6" }
     { print }' "$ZV/fold-coordbrk.zmx" > "$SF/fold45.zmx"
sf_fold45() {
    sf_pupil "$1" "$SF/fold45.zmx" f45 6 || { cat "$SF/f45.err"; return 1; }
    [ -s "$SF/fo.k" ] || sf_pupil "$1" "$ZV/singlet-fold.zmx" fo 6 || return 1
    grep -E 'spot:|RMS radius|centroid x|RMS .* waves|chief ray:' "$SF/fo.rec" > "$SF/fo.k"
    grep -q '^Coordinate breaks: 2; ' "$SF/f45.rec" && grep -q '^Mirrors: 1; ' "$SF/f45.rec" &&
    grep -E 'spot:|RMS radius|centroid x|RMS .* waves|chief ray:' "$SF/f45.rec" > "$SF/f45.k" &&
    cmp "$SF/fo.k" "$SF/f45.k"
}
check "--pupil, 45-degree fold by two COORDBRK: spots and wavefronts as the fold at normal incidence" sf_fold45 "$BIN"
check "--pupil, 45-degree fold: the same under ASan/UBSan" sf_fold45 "$ASAN"

# Read, written, read: .zmx -> prescription (coordbrk lines) -> .zmx (TYPE COORDBRK,
# PARM 1-6) -> prescription: a fixed point with the file's numbers.
sf_cb_back() {
    (cd "$SF" && "$1" --to-thickness -i fold45.zmx cb.rx 2>/dev/null) &&
    grep -q '^coordbrk  *0  *decenter 0 0 tilt 45 0 0 order 0$' "$SF/cb.rx" &&
    grep -q '^coordbrk  *-18  *decenter 0 0 tilt 45 0 0 order 0$' "$SF/cb.rx" || { cat "$SF/cb.rx"; return 1; }
    (cd "$SF" && "$1" --to-zmx -i cb.rx cb.zmx 2>/dev/null) &&
    [ "$(grep -c 'TYPE COORDBRK' "$SF/cb.zmx")" -eq 2 ] && grep -q 'PARM 3 45' "$SF/cb.zmx" &&
    grep -q 'DISZ -18' "$SF/cb.zmx" || { cat "$SF/cb.zmx"; return 1; }
    (cd "$SF" && "$1" --to-thickness -i cb.zmx cb2.rx 2>/dev/null && "$1" --to-zmx -i cb2.rx cb2.zmx 2>/dev/null) &&
    cmp "$SF/cb.rx" "$SF/cb2.rx" && cmp "$SF/cb.zmx" "$SF/cb2.zmx"
}
check "COORDBRK read -> prescription -> .zmx -> read: the same numbers (fixed point)" sf_cb_back "$BIN"

# A lens decentred by 0.5 mm (a break, the lens, the inverse break: order 1, negated):
# the axis point images on the lens's own axis, 0.5 off the old one (the chief ray
# runs down the lens's axis), while first order takes the break as zero (0) and says so.
cat > "$SF/dec.rx" <<'RX'
thickness
title plano-convex f 1000 decentred 0.5
unit mm
wavelengths d
epd 10
field angle 0
index air
coordbrk  0    decenter 0 0.5
500       2    1.5  stop
plane     0    air
coordbrk  998  decenter 0 -0.5 order 1
RX
sf_dec() {
    sf_pupil "$1" "$SF/dec.rx" de 2 || { cat "$SF/de.err"; return 1; }
    grep -q '^Coordinate breaks: 2; first-order data .* with every tilt and decentre zero' "$SF/de.rec" &&
    grep -q 'chief ray: paraxial image height 0 (0 at the image plane), real 0.5 ' "$SF/de.rec" &&
    grep -q 'centroid x 0 y 0.5' "$SF/de.rec" || { cat "$SF/de.rec"; return 1; }
}
check "--pupil, a lens decentred 0.5: the image 0.5 off the axis; first order says it takes the break as zero" sf_dec "$BIN"

# Refused: a coordinate break as the stop, a bad order, a bad key (FILE:LINE, exit 2).
sf_cb_bad() {
    printf 'thickness\nepd 10\nindex air\n50 5 N-BK7\ncoordbrk 0 tilt 1 0 0 order 2\n-50 40 air\n' > "$SF/bad1.rx"
    (cd "$SF" && "$1" --prescription -i bad1.rx b1.rec > /dev/null 2> b1.err); [ $? -eq 2 ] &&
    grep -q 'bad1.rx:5: order: 0 (decentre, then tilt) or 1' "$SF/b1.err" || { cat "$SF/b1.err"; return 1; }
    printf 'thickness\nepd 10\nindex air\n50 5 N-BK7\ncoordbrk 0 twist 1\n-50 40 air\n' > "$SF/bad2.rx"
    (cd "$SF" && "$1" --prescription -i bad2.rx b2.rec > /dev/null 2> b2.err); [ $? -eq 2 ] &&
    grep -q "bad2.rx:5: 'twist' is not a coordinate-break key" "$SF/b2.err" || { cat "$SF/b2.err"; return 1; }
}
check "bad coordinate breaks refused with FILE:LINE (order 2, an unknown key)" sf_cb_bad "$BIN"

# The design module takes folded lenses (first order unfolded, rays folded; t_44 has
# the rest): the Cassegrain's mirror separation d = 150 -+ 0.1 changes its efl as the
# mirror equation says, f1 f2 / (f1 + f2 - d) with f1 200, f2 -62.5: 992.063492 at
# d 150.1 (t 1 = -150.1), 1008.06452 at 149.9.
sf_design_cass() {
    printf 'tol t 1 0.1\n' > "$SF/c.tol"
    printf '%s\n%s\nsens\n' "$SF/cass.rx" "$SF/c.tol" > "$SF/ct.in"
    (cd "$SF" && "$1" --tolerance -i ct.in ct.rec > /dev/null 2> ct.err) || { cat "$SF/ct.err"; return 1; }
    awk '$1 == "t" && $2 == 1 { e1 = $8; e2 = $9 }
         END { a = -12500 / (137.5 - 150.1); b = -12500 / (137.5 - 149.9)
               printf "efl %s %s, mirror equation %.9g %.9g\n", e1, e2, a, b
               exit !(e1 != "" && (e1 - a) ^ 2 < 1e-12 && (e2 - b) ^ 2 < 1e-10) }' "$SF/ct.rec"
}
check "--tolerance on a Cassegrain: efl at d -+ 0.1 as the mirror equation (folded lenses accepted)" sf_design_cass "$BIN"
