# t_42_beam_oblique.sh -- the beam's oblique incidence on the cornea (issue 21, section
# 46; rig_api.spot_chain / spot_pose / cornea_curvature, the scan in rig_api.spots, the
# --rig 'beam' report's new lines): the engine against models written in
# tests/rig/t_oblique.c (rays traced off a sphere at 30 deg against Coddington, theta 0
# = the apex model bit for bit, normal-section circles, Self's formula per plane), both
# builds; the dialogue's apex-pose line against Coddington and Self's formula computed
# here in awk from the report's own inputs; the old lines unchanged; the record replays
# exactly; the wide-zone rig (blind at the apex) reports a stand-in pose and its scan.
for b in t_oblique; do
    for d in obj asan; do
        x=$TOP/build/$d/rig_tests/$b
        if [ ! -x "$x" ]; then fail "$x (not built)"; continue; fi
        "$x" "$TOP/golden/rig/example.rig" "$TOP/golden/rig/wide-zone.rig" > "$WORK/obl.out" 2>&1
        rc=$?
        p=$(grep -c '^PASS' "$WORK/obl.out"); f=$(grep -c '^FAIL' "$WORK/obl.out")
        PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
        grep '^FAIL' "$WORK/obl.out" | sed "s|^|$b ($d): |"
        [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || fail "$b ($d) exited $rc"
        [ "$p" -ge 30 ] || fail "$b ($d): only $p checks passed"
    done
done
D=$WORK/oblique
mkdir -p "$D"
obl_session() {   # obl_session DIR RIG: the beam report on the simulator
    mkdir -p "$1"
    printf '%s\n' "$2" sim - beam quit > "$1/in"
    (cd "$1" && "$BIN" --rig -i in r.rec > out 2> err)
}
obl_old_lines() {   # the apex model's figures as before, and before the new lines
    obl_session "$D/a" "$TOP/golden/rig/example.rig" || return 1
    grep -q 'cornea 0.2 mm, detector 3.534 mm' "$D/a/r.rec" &&
        grep -q '^Balanced lens .* f 36.0' "$D/a/r.rec" &&
        grep -q '0.0014 um per axis now' "$D/a/r.rec" &&
        awk '/^Beam radius/ { r = NR } /^Oblique incidence/ { o = NR }
             END { exit !(r > 0 && o > r) }' "$D/a/r.rec"
}
check "rig beam oblique: the normal-incidence lines unchanged, the oblique ones after" obl_old_lines
# The apex pose: the waist (beam_diameter_mm / 2, no beam_waist) sits on the cornea, so
# past the mirror of focal length f (Self, s = 0): s' = f zR^2 / (f^2 + zR^2) ... written
# as s' = f - f^3/(f^2 + zR^2), w0' = w0 / sqrt(1 + (zR/f)^2), and w at the detector
# plane (L mm) = w0' sqrt(1 + ((L - s')/zR')^2).  Coddington: f_t = -(R/2) cos i,
# f_s = -R / (2 cos i).  The detector meets this beam square on: the footprint is the
# section, the larger axis the tangential one.
obl_apex() {
    awk 'function self_w(f, w0, lm, L,   zr, s2, w1, zr1) {
             zr = 3.14159265358979 * w0 * w0 / lm
             s2 = f - f * f * f / (f * f + zr * zr)
             w1 = w0 / sqrt(1 + (zr / f) ^ 2)
             zr1 = 3.14159265358979 * w1 * w1 / lm
             return w1 * sqrt(1 + ((L - s2) / zr1) ^ 2) }
         function rel(a, b) { return (a - b < 0 ? b - a : a - b) / (b < 0 ? -b : b) }
         /^Beam, apex pose:/ { L = $(NF - 9); R = $(NF - 1) + 0 }
         /^Laser: no beam_waist/ { w0 = $12; lm = $(NF - 1) * 1e-6 }
         /^Oblique incidence .*apex pose/ {
             for (i = 1; i <= NF; i++) {
                 if ($i == "incidence") inc = $(i + 1)
                 if ($i == "lengths") { ft = $(i + 1); fs = $(i + 3) }
                 if ($i == "spot") { wa = $(i + 1); wb = $(i + 3) }
             }
         }
         END {
             c = cos(inc * 3.14159265358979 / 180)
             cft = -R / 2 * c; cfs = -R / (2 * c)
             wt = self_w(cft, w0, lm, L); ws = self_w(cfs, w0, lm, L)
             printf "L %s R %s w0 %s inc %s: f %s %s (Coddington %.6g %.6g), spot %s x %s " \
                    "(Self %.6g x %.6g)\n", L, R, w0, inc, ft, fs, cft, cfs, wa, wb, wt, ws
             exit !(L > 0 && R > 0 && w0 > 0 && inc > 19.99 && inc < 20.01 &&
                    rel(ft, cft) < 2e-5 && rel(fs, cfs) < 2e-5 &&
                    rel(wa, wt) < 2e-4 && rel(wb, ws) < 2e-4) }' "$D/a/r.rec"
}
check "rig beam oblique: the apex pose's line = Coddington and Self's formula (awk)" obl_apex
obl_scan() {   # the scan line: the incidence grows past the apex's; large >= small
    awk '/^Scan: .* poses have a beam/ { n = $2; tot = $4; inc = $(NF - 7) }
         /^Largest detector spot/ { big = $4; bmin = $6 }
         /^Smallest detector spot/ { small = $4 }
         END { exit !(n > 50 && tot == 201 && inc > 30 && big >= small && small > 0 &&
                      bmin <= big) }' "$D/a/r.rec"
}
check "rig beam oblique: the scan's incidence, largest and smallest spot reported" obl_scan
# the Fresnel line: R at normal incidence ((n-1)/(n+1))^2 and at the apex pose's 20 deg
# from Hecht's formulas in awk (unpolarized: the mean), n 1.376; the lowest no higher;
# the scan's balanced lens no worse than the apex model's on the same scan
obl_fresnel() {
    awk 'function hr(th,   n, ci, si, ct, rs, rp) { n = 1.376; ci = cos(th); si = sin(th)
             ct = sqrt(1 - si * si / (n * n)); rs = (ci - n * ct) / (ci + n * ct)
             rp = (n * ci - ct) / (n * ci + ct); return (rs * rs + rp * rp) / 2 }
         function rel(a, b) { return (a - b < 0 ? b - a : a - b) / b }
         /^Cornea.s reflectance/ { for (i = 1; i <= NF; i++) {
                 if ($i == "unpolarized):") { r0 = $(i + 1); ra = $(i + 5) }
                 if ($i == "lowest") rl = $(i + 1) } }
         /^Balanced over the scan/ { for (i = 1; i <= NF; i++) {
                 if ($i == "cornea" && $(i - 1) == "worst") { c = $(i + 1) + 0; d = $(i + 5) + 0 }
             }
             ac = $(NF - 3) + 0; ad = $(NF - 1) + 0 }
         END { w0 = hr(0); wa = hr(20 * atan2(0, -1) / 180)
               printf "R0 %s (%.6g), apex %s (%.6g), lowest %s; scan lens worst %s/%s, apex lens %s/%s\n", r0, w0, ra, wa, rl, c, d, ac, ad
               exit !(rel(r0, w0) < 1e-3 && rel(ra, wa) < 1e-3 && rl <= ra && c > 0 && d > 0 &&
                      (c > d ? c : d) <= (ac > ad ? ac : ad)) }' "$D/a/r.rec"
}
check "rig beam oblique: the cornea's Fresnel reflectance (normal, apex pose: Hecht in awk), the lens balanced over the scan no worse than the apex model's" obl_fresnel
obl_pol() {   # a linearly polarized laser: the line says so, the s share is not 0.5; replays
    mkdir -p "$D/p" && cp "$TOP/golden/rig/example.rig" "$D/p/pol.rig" &&
    echo "laser_polarization 0 0 1" >> "$D/p/pol.rig" &&
    obl_session "$D/p" "$D/p/pol.rig" || return 1
    grep -q "^Cornea's reflectance (Fresnel, n 1.376, the laser's field along 0 0 1):" "$D/p/r.rec" &&
        ! grep "^Cornea's reflectance" "$D/p/r.rec" | grep -q ', 0.5 of the power in s' &&
        grep input: "$D/p/r.rec" > "$D/p/in2" &&
        (cd "$D/p" && "$BIN" --rig r2.rec < in2 > /dev/null 2>&1) && cmp "$D/p/r.rec" "$D/p/r2.rec"
}
check "rig beam oblique: laser_polarization 0 0 1 reported, its s share, the record replays" obl_pol
obl_replay() {
    grep input: "$D/a/r.rec" > "$D/a/in2"
    (cd "$D/a" && "$BIN" --rig r2.rec < in2 > /dev/null 2>&1) && cmp "$D/a/r.rec" "$D/a/r2.rec"
}
check "rig beam oblique: the grep'd record replays exactly" obl_replay
check "rig beam oblique: ASan build, the same session" sh -c "cd '$D/a' && LENSMAT_LIBDIR='$TOP/build/asan/lib' '$ASAN' --rig r3.rec < in2 > /dev/null 2>&1 && cmp r.rec r3.rec"
obl_wide() {   # blind at the apex: a stand-in pose, no apex line, incidence past 40 deg
    obl_session "$D/w" "$TOP/golden/rig/wide-zone.rig" || return 1
    grep -q "^Beam: the apex pose does not solve (m2 or its mount blocks" "$D/w/r.rec" &&
        grep -q "^Beam, that pose: laser to m1" "$D/w/r.rec" &&
        grep -q '^Oblique incidence, apex pose: none' "$D/w/r.rec" &&
        awk '/^Scan: .* poses have a beam/ { inc = $(NF - 7) } END { exit !(inc > 40) }' \
            "$D/w/r.rec"
}
check "rig beam oblique: the wide-zone rig (blind at the apex): a stand-in pose, 40+ deg" obl_wide
