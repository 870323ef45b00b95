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
