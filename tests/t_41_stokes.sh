# t_41_stokes.sh -- Stokes parameters in the hits output and polarized sources beyond
# linear (issue 21): `pol right|left`, `pol ellipse AZ CHI`, `pol jones JX JY PX PY`,
# `pol stokes S1 S2 S3` (partially polarized)
# (src/trace/scene_polar.c, tr_source.c, tr_polar.c) and the hits' S0..S3 columns
# (scene_out.c, scene_polout.c).  Every expected value is Mueller calculus written here
# in awk from the documented conventions (doc/trace.md: fields exp(i(kz - wt)), S3 =
# 2 Im(Ex* Ey), a retarder diag(e^{-i d/2}, e^{i d/2}) in its fast/slow frame), never
# numbers the engine printed: circular light through a polarizer at four angles and
# through wave plates, the ellipse's (azimuth, ellipticity) formulas in three frames,
# the handedness flip of a normal-incidence reflection (mirror and glass, R from
# Fresnel), the hits' columns against the polar table row by row and the summary, the
# two engine paths (coherency and PRT) agreeing for an elliptical source, .npy and
# HDF5 read back by NumPy/h5py, scenes without polarization byte-identical to the main
# build's, and the refusals with FILE:LINE; the engine's elliptical sources through its
# table in tests/trace/t_stokes.c.

cd "$TOP" || return 1
unit "$TOP/build/obj/trace_tests/t_stokes"    # the engine's side (tests/trace/t_stokes.c)
unit "$TOP/build/asan/trace_tests/t_stokes"
SW=$WORK/stokes
mkdir -p "$SW"
PY=/usr/bin/python3
# LENSMAT_MAIN: a build from before a change to compare with, byte for byte (the merge
# of the Stokes columns was checked so against the build before it); unset: skipped,
# and the columns without polarization are checked against the list below instead
MAINBIN=${LENSMAT_MAIN:-}

# trace_in BIN DIR SCENE: trace DIR/SCENE (answers recorded in DIR/t.rec)
trace_in() (
    cd "$2" && printf 'scene\n%s\nn\n' "$3" > t.in && "$1" --trace -i t.in t.rec > t.out 2> t.err
)

# The Mueller calculus of the test (awk functions, prepended to each program):
#   pol_m(th, M)      ideal linear polarizer, transmission axis at th (radians)
#   ret_m(th, d, M)   linear retarder, fast axis th, retardance d: R(-2th) M0(d) R(2th),
#                     M0 from w' = e^{i d} w (w = Ex* Ey: the slow y component delayed)
#   mir_m(r, M)       normal-incidence reflection of reflectance r, the frame following
#                     the ray (x' kept, y' = dir x x' reversed): r diag(1, 1, -1, -1)
#   mv(M, s, o)       o = M s;  ell(psi, chi, s): the ellipse's unit Stokes vector
MUELLER='
function zero(M,  i, j) { for (i = 0; i < 4; i++) for (j = 0; j < 4; j++) M[i, j] = 0 }
function pol_m(th, M,  c, s) { zero(M); c = cos(2 * th); s = sin(2 * th)
    M[0,0] = .5; M[0,1] = .5 * c; M[0,2] = .5 * s; M[1,0] = .5 * c; M[1,1] = .5 * c * c
    M[1,2] = .5 * c * s; M[2,0] = .5 * s; M[2,1] = .5 * c * s; M[2,2] = .5 * s * s }
function rot_m(a, M) { zero(M); M[0,0] = 1; M[3,3] = 1
    M[1,1] = cos(a); M[1,2] = sin(a); M[2,1] = -sin(a); M[2,2] = cos(a) }
function mm(A, B, C,  i, j, k) { for (i = 0; i < 4; i++) for (j = 0; j < 4; j++) {
    C[i, j] = 0; for (k = 0; k < 4; k++) C[i, j] += A[i, k] * B[k, j] } }
function ret_m(th, d, M,  R1, R2, M0, T) { zero(M0); M0[0,0] = 1; M0[1,1] = 1
    M0[2,2] = cos(d); M0[2,3] = -sin(d); M0[3,2] = sin(d); M0[3,3] = cos(d)
    rot_m(2 * th, R1); rot_m(-2 * th, R2); mm(M0, R1, T); mm(R2, T, M) }
function mir_m(r, M) { zero(M); M[0,0] = r; M[1,1] = r; M[2,2] = -r; M[3,3] = -r }
function mv(M, s, o,  i, k) { for (i = 0; i < 4; i++) { o[i] = 0
    for (k = 0; k < 4; k++) o[i] += M[i, k] * s[k] } }
function ell(p, c, s) { s[0] = 1; s[1] = cos(2 * c) * cos(2 * p); s[2] = cos(2 * c) * sin(2 * p)
    s[3] = sin(2 * c) }
function ab(x) { return x < 0 ? -x : x }
# the row of a CSV (header already read into col[]) against o[]: worst difference
function off(o,  k, e, m) { m = 0; for (k = 0; k < 4; k++) { e = ab($col["S" k] - o[k])
    if (e > m) m = e } return m }
BEGIN { FS = ","; pi = atan2(0, -1); deg = pi / 180 }
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
'

# right-circular light through an ideal linear polarizer at 0, 30, 75, 120 degrees:
# S = M_pol (1, 0, 0, -1) = (1/2, cos 2t / 2, sin 2t / 2, 0)
stokes_polarizer() (
    d=$SW/pol; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    for a in 0 30 75 120; do
        awk -v a="$a" 'BEGIN { t = a * atan2(0, -1) / 180
            printf "plane refract 1 1 polarizer %.17g %.17g 0 at 0 0 1 normal 0 0 1 disc 5\n", cos(t), sin(t)
            print "plane detect at 0 0 3 normal 0 0 1 disc 5"
            print "source ray from 0 0 0 dir 0 0 1 pol right"; print "output hits h.csv" }' > p.scene &&
        trace_in "$BIN" "$d" p.scene || return 1
        awk -v a="$a" "$MUELLER"'NR == 2 { s[0] = 1; s[1] = 0; s[2] = 0; s[3] = -1
            pol_m(a * deg, M); mv(M, s, o); e = off(o); n++
            printf "%s deg: S = %s %s %s %s, Mueller %.6f %.6f %.6f %.6f, worst %.2g\n", a,
                $col["S0"], $col["S1"], $col["S2"], $col["S3"], o[0], o[1], o[2], o[3], e
            if (e > 1e-12) bad = 1 } END { exit !(n == 1 && !bad) }' h.csv || return 1
    done
)
check "right-circular light through a polarizer at 0/30/75/120 deg: S = (1/2, cos 2t/2, sin 2t/2, 0) (Mueller, 1e-12)" \
    stokes_polarizer

# wave plates: right and left circular through a quarter-wave plate at 45 deg become
# linear (S3 ~ 0, DoP 1: (1, -1, 0, 0) and (1, 1, 0, 0)); an elliptical state through a
# 60-degree retarder at 60 deg and a half-wave plate at -20 deg, each against Mueller
stokes_plates() (
    d=$SW/plates; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    printf '%s\n' 'plane refract 1 1 qwp 0.70710678118654752 0.70710678118654752 0 at 0 0 1 normal 0 0 1 disc 5' \
        'plane detect at 0 0 3 normal 0 0 1 disc 5' 'source ray from 0 0 0 dir 0 0 1 pol right' \
        'source ray from 0 0 0 dir 0 0 1 pol left' 'output hits h.csv' > q.scene &&
    trace_in "$BIN" "$d" q.scene || return 1
    awk "$MUELLER"'NR > 1 { s[0] = 1; s[1] = 0; s[2] = 0; s[3] = ($col["ray"] == 0 ? -1 : 1)
        ret_m(45 * deg, pi / 2, M); mv(M, s, o); e = off(o)
        dop = sqrt($col["S1"] ^ 2 + $col["S2"] ^ 2 + $col["S3"] ^ 2) / $col["S0"]
        printf "%s: S = %s %s %s %s (Mueller %g %g %g %g), DoP %.15f\n", s[3] < 0 ? "right" : "left",
            $col["S0"], $col["S1"], $col["S2"], $col["S3"], o[0], o[1], o[2], o[3], dop
        if (e > 1e-12 || ab($col["S3"]) > 1e-12 || ab(dop - 1) > 1e-12 || ab(o[3]) > 1e-15) bad = 1; n++ }
        END { exit !(n == 2 && !bad) }' h.csv || return 1
    printf '%s\n' 'plane refract 1 1 retarder 0.5 0.86602540378443865 0 60 at 0 0 1 normal 0 0 1 disc 5' \
        'plane detect at 0 0 3 normal 0 0 1 disc 5' 'source ray from 0 0 0 dir 0 0 1 pol ellipse 10 25' \
        'output hits r.csv' > r.scene &&
    sed 's/retarder 0.5 0.86602540378443865 0 60/hwp 0.93969262078590838 -0.34202014332566873 0/; s/r.csv/w.csv/' \
        r.scene > w.scene && trace_in "$BIN" "$d" r.scene && trace_in "$BIN" "$d" w.scene || return 1
    awk -v t=60 -v r=60 "$MUELLER"'NR == 2 { ell(10 * deg, 25 * deg, s); ret_m(t * deg, r * deg, M)
        mv(M, s, o); e = off(o); printf "retarder: worst %.2g\n", e; exit !(e < 1e-12) }' r.csv &&
    awk -v t=-20 -v r=180 "$MUELLER"'NR == 2 { ell(10 * deg, 25 * deg, s); ret_m(t * deg, r * deg, M)
        mv(M, s, o); e = off(o); printf "hwp: worst %.2g, S3 %s (Mueller %g)\n", e, $col["S3"], o[3]
        exit !(e < 1e-12 && $col["S3"] * s[3] < 0) }' w.csv
)
check "a quarter-wave plate at 45 deg makes circular light linear (S3 ~ 0, DoP 1); a retarder and a half-wave plate on elliptical light = Mueller" \
    stokes_plates

# the ellipse's formulas S/S0 = (cos 2c cos 2p, cos 2c sin 2p, sin 2c) for five states
# along z, for a cone about +x (every ray within 25 deg of the reference: the frame's
# other rule) and with `polarization ref 0 1 0`; `pol jones`: S1 = (a^2 - b^2)/N,
# S2 = 2ab cos(py - px)/N, S3 = 2ab sin(py - px)/N; S0 = the hit's power
stokes_ellipse() (
    d=$SW/ell; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    { echo 'plane detect at 0 0 3 normal 0 0 1 disc 5'
      for pc in "0 0" "30 10" "-60 -20" "135 45" "100 -45"; do
          echo "source ray from 0 0 0 dir 0 0 1 pol ellipse $pc"; done
      echo 'source ray from 0 0 0 dir 0 0 1 pol jones 1 2 10 70'
      echo 'output hits h.csv'; echo 'polarization on'; } > e.scene &&
    printf '%s\n' 'sphere detect center 0 0 0 radius 10' \
        'source cone from 0 0 0 dir 1 0 0 angle 20 rings 4 pol ellipse 30 10' 'output hits c.csv' \
        'polarization on' > c.scene &&
    printf '%s\n' 'plane detect at 0 0 3 normal 0 0 1 disc 5' 'polarization on ref 0 1 0' \
        'source cone from 0 0 0 dir 0 0 1 angle 10 rings 3 pol ellipse 30 10' 'output hits y.csv' > y.scene &&
    trace_in "$BIN" "$d" e.scene && trace_in "$BIN" "$d" c.scene && trace_in "$BIN" "$d" y.scene || return 1
    awk "$MUELLER"'NR > 1 { r = $col["ray"]
        if (r == 0) ell(0, 0, s); if (r == 1) ell(30 * deg, 10 * deg, s)
        if (r == 2) ell(-60 * deg, -20 * deg, s); if (r == 3) ell(135 * deg, 45 * deg, s)
        if (r == 4) ell(100 * deg, -45 * deg, s)
        if (r == 5) { s[0] = 1; s[1] = (1 - 4) / 5; s[2] = 4 * cos(60 * deg) / 5; s[3] = 4 * sin(60 * deg) / 5 }
        e = off(s) + ab($col["S0"] - $col["power"]); if (e > m) m = e; n++ }
        END { printf "%d states along z: worst %.2g\n", n, m; exit !(n == 6 && m < 1e-12) }' h.csv &&
    for f in c.csv y.csv; do
        awk "$MUELLER"'NR > 1 { ell(30 * deg, 10 * deg, s); for (k = 0; k < 4; k++) s[k] *= $col["S0"]
            e = off(s); if (e > m) m = e; n++; p += $col["power"] }
            END { printf "%s: %d rays, worst %.2g\n", FILENAME, n, m; exit !(n > 30 && m < 1e-12 && ab(p - 1) < 1e-12) }' $f || return 1
    done
)
check "pol ellipse AZ CHI / pol jones: S1..S3 = the (azimuth, ellipticity) formulas (1e-12), in the reference's frame and its 25-degree twin" \
    stokes_ellipse

# normal incidence flips the handedness: a mirror (R = 1) and bare glass n = 1.5
# (R = ((n-1)/(n+1))^2 = 0.04 back, T = 0.96 through, handedness kept): right-circular
# comes back left (S3 = +R), 30-degree linear comes back at -30 (S2 = -R sin 60)
stokes_reflect() (
    d=$SW/refl; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    for k in mirror glass; do
        { [ $k = mirror ] && echo 'plane mirror at 0 0 1 normal 0 0 1 disc 5' ||
              echo 'plane refract 1 1.5 at 0 0 1 normal 0 0 1 disc 5'
          echo 'plane detect at 0 0 -1 normal 0 0 1 disc 5'
          echo 'plane detect at 0 0 3 normal 0 0 1 disc 5'
          echo 'source ray from 0 0 0 dir 0 0 1 pol right'
          echo 'source ray from 0 0 0 dir 0 0 1 pol 0.86602540378443865 0.5 0'
          echo 'polarization on'; echo "output hits $k.csv"; } > $k.scene &&
        trace_in "$BIN" "$d" $k.scene || return 1
    done
    awk "$MUELLER"'FNR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        { if (FILENAME == "mirror.csv") R = 1; else R = ((1.5 - 1) / (1.5 + 1)) ^ 2
        r = $col["ray"]; s[0] = 1; s[1] = r ? cos(60 * deg) : 0; s[2] = r ? sin(60 * deg) : 0; s[3] = r ? 0 : -1
        if ($col["z"] < 0) { mir_m(R, M); mv(M, s, o); back++ }
        else { for (k = 0; k < 4; k++) o[k] = (1 - R) * s[k]; through++ }
        e = off(o); if (e > m) m = e
        if ($col["z"] < 0 && r == 0 && !($col["S3"] > 0)) flip = 1
        printf "%s ray %d %s: S = %s %s %s %s\n", FILENAME, r, $col["z"] < 0 ? "back" : "through",
            $col["S0"], $col["S1"], $col["S2"], $col["S3"] }
        END { printf "worst %.2g\n", m; exit !(back == 4 && through == 2 && m < 1e-12 && !flip) }' \
        mirror.csv glass.csv
)
check "normal-incidence reflection (mirror, glass R = 0.04) flips the handedness: right comes back left, S = R diag(1,1,-1,-1) S" \
    stokes_reflect

# A coated, retarding singlet with reflections followed, an elliptical cone, two
# threads: each hit's S0..S3 in the hits CSV is the polar table's row (the same text),
# S0 the hit's power (1e-12), |S1..S3| <= S0, and the S0 of all hits the summary's
# detected power
stokes_vs_table() (
    d=$SW/tab; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    printf '%s\n' 'cap refract 1 1.5 coating c vertex 0 0 0 radius 20 aperture 8' \
        'coating c layer 1.38 100 layer 2.0 70' 'cap refract 1.5 1 retarder 1 1 0 30 vertex 0 0 4 radius -20 aperture 8' \
        'sphere detect center 0 0 0 radius 50' 'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 12 pol ellipse 20 15' \
        'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 6 lambda 450 650' \
        'threads 2' 'output hits h.csv' 'output polar p.csv' 'output summary s.sum' > t.scene &&
    trace_in "$1" "$d" t.scene || return 1
    [ "$(wc -l < h.csv)" -gt 1000 ] && [ "$(wc -l < h.csv)" = "$(wc -l < p.csv)" ] || return 1
    head -1 h.csv | grep -q ',opl,lambda_nm,S0,S1,S2,S3$' || return 1
    awk -F, 'FNR == 1 { for (i = 1; i <= NF; i++) c[FILENAME, $i] = i; next }
        FILENAME == "p.csv" { for (k = 0; k < 4; k++) t[FNR, k] = $c["p.csv", "S" k]
                              id[FNR] = $1 "," $2 "," $3 "," $c["p.csv", "x"] "," $c["p.csv", "z"]; next }
        FILENAME == "h.csv" { n++; h = "h.csv"
            if (id[FNR] != $1 "," $2 "," $3 "," $c[h, "x"] "," $c[h, "z"]) bad++
            for (k = 0; k < 4; k++) if ($c[h, "S" k] != t[FNR, k]) bad++
            e = $c[h, "S0"] - $c[h, "power"]; if (e < 0) e = -e; if (e > 1e-12 * $c[h, "power"] + 1e-300) bad++
            if ($c[h, "S1"] ^ 2 + $c[h, "S2"] ^ 2 + $c[h, "S3"] ^ 2 > $c[h, "S0"] ^ 2 * (1 + 1e-12)) bad++
            sum += $c[h, "S0"]; next }
        { split($0, w, " "); if (w[1] == "detected") det = w[2] }
        END { e = sum - det; if (e < 0) e = -e
              printf "%d hits, %d differences, sum S0 %.17g, detected %.17g\n", n, bad, sum, det
              exit !(n > 1000 && bad == 0 && e < 1e-12 * det) }' p.csv h.csv s.sum
)
check "the hits' S0..S3 = the polar table's rows (coated retarding lens, reflections, two threads, two wavelengths); S0 = power; sum S0 = detected" \
    stokes_vs_table "$BIN"
check "the same under ASan/UBSan" stokes_vs_table "$ASAN"

# The coherency path (no polarization: s, p powers only) and the PRT path (polarization
# on) are two implementations: for elliptical and circular cones through a tilted glass
# plate with reflections followed, each hit's power_s and power_p agree to 1e-12;
# without polarization the hits have no S columns
stokes_paths() (
    d=$SW/paths; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    printf '%s\n' 'plane refract 1 1.6 at 0 0 5 normal 0.5 0 0.8660254037844386 disc 20' \
        'plane refract 1.6 1 at 0 0 8 normal 0.5 0 0.8660254037844386 disc 20' \
        'plane detect at 0 0 30 normal 0 0 1 disc 200' 'plane detect at 0 0 -30 normal 0 0 1 disc 200' \
        'source cone from 0 0 0 dir 0 0 1 angle 25 rings 8 pol ellipse 40 -20' \
        'source cone from 0 0 0 dir 0 0 1 angle 25 rings 8 pol left' \
        'source cone from 0 0 0 dir 0 0 1 angle 25 rings 8 pol jones 0.3 1 0 -130' \
        'source cone from 0 0 0 dir 0 0 1 angle 25 rings 8 pol stokes 0.2 -0.5 0.4' 'output hits a.csv' > a.scene &&
    { sed 's/a.csv/b.csv/' a.scene; echo 'polarization on'; } > b.scene &&
    trace_in "$BIN" "$d" a.scene && trace_in "$BIN" "$d" b.scene || return 1
    head -1 a.csv | grep -q ',opl$' && head -1 b.csv | grep -q ',opl,S0,S1,S2,S3$' || return 1
    [ "$(wc -l < a.csv)" = "$(wc -l < b.csv)" ] || return 1
    paste -d, a.csv b.csv | awk -F, 'NR > 1 {
        for (i = 1; i <= 10; i++) if ($i != $(i + 15)) bad++
        for (i = 11; i <= 12; i++) { e = $i - $(i + 15); if (e < 0) e = -e; if (e > 1e-12 * $13) bad++ }
        if ($11 != $12) uneven++; n++ }
        END { printf "%d hits, %d differences, %d with s != p\n", n, bad, uneven; exit !(n > 400 && bad == 0 && uneven > 100) }'
)
check "elliptical, circular and partially polarized sources: the coherency path's power_s, power_p = the PRT path's (1e-12); no S columns without polarization" \
    stokes_paths

# .npy and HDF5: the S columns read back by NumPy (h5py) to the CSV's values, bit for bit
stokes_npy() (
    d=$SW/npy; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    printf '%s\n' 'plane refract 1 1 qwp 1 0 0 at 0 0 1 normal 0 0 1 disc 5' 'plane detect at 0 0 3 normal 0 0 1 disc 5' \
        'source cone from 0 0 0 dir 0 0 1 angle 30 rings 5 pol ellipse 25 -10 lambda 500' 'output hits h.csv' > c.scene &&
    sed 's/h.csv/h.npy/' c.scene > n.scene && sed 's/h.csv/h.h5/' c.scene > f.scene &&
    trace_in "$BIN" "$d" c.scene && trace_in "$BIN" "$d" n.scene && trace_in "$BIN" "$d" f.scene || return 1
    "$PY" - <<'EOF'
import csv, numpy
rows = list(csv.reader(open('h.csv')))
head, body = rows[0], rows[1:]
a = numpy.load('h.npy')
assert a.dtype.names == tuple(head), (a.dtype.names, head)
assert head[-5:] == ['lambda_nm', 'S0', 'S1', 'S2', 'S3'], head
assert len(a) == len(body) > 50
for k in ('S0', 'S1', 'S2', 'S3', 'power'):
    i = head.index(k)
    assert all(float(r[i]) == v for r, v in zip(body, a[k])), k
    assert a[k].dtype == numpy.float64
assert abs(a['S3'] / a['S0']).max() > 0.1 and abs(a['S0'] - a['power']).max() < 1e-12 * a['power'].max()
try:
    import h5py
except ImportError:
    print('no h5py: HDF5 not read'); raise SystemExit(0)
h = h5py.File('h.h5')['hits'][()]
assert h.dtype.names == a.dtype.names and all((h[k] == a[k]).all() for k in a.dtype.names)
print('npy and h5 ok', len(a), 'rows')
EOF
)
if [ -x "$PY" ] && "$PY" -c 'import numpy' 2> /dev/null; then
    check ".npy (and HDF5): NumPy reads S0..S3 after lambda_nm, equal to the CSV's numbers to the bit" stokes_npy
else
    echo "SKIP t_41: python3 with numpy not found: the .npy S columns were not read back"
fi

# Without polarization the hits files are byte for byte the main build's: the example
# singlet (CSV), the prism (.npy, HDF5, csv17, segments) and a linearly polarized source;
# the polar table of unpolarized and linear sources through a coated retarding lens too
stokes_same() (
    d=$SW/same; rm -rf "$d"; mkdir -p "$d/new" "$d/old" && cd "$d" || return 1
    cp "$TOP/scenes/singlet.scene" "$TOP/scenes/prism.scene" "$TOP/scenes/prism.obj" new/ &&
    sed 's/^output hits prism-hits.csv$/output hits prism-hits.npy/' new/prism.scene > new/pn.scene &&
    { sed 's/^output hits prism-hits.csv$/output all prism-all.h5/; /^output segments/d' new/prism.scene; } > new/ph.scene &&
    sed 's/^output hits prism-hits.csv$/output hits prism-17.csv csv17/' new/prism.scene > new/p17.scene &&
    printf '%s\n' 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 8' 'plane detect at 0 0 30 normal 0 0 1 disc 50' \
        'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 10 pol 0 1 0' 'output hits lin.csv' > new/lin.scene &&
    printf '%s\n' 'cap refract 1 1.5 coating c vertex 0 0 0 radius 20 aperture 8' 'coating c layer 1.38 100' \
        'cap refract 1.5 1 retarder 1 1 0 30 vertex 0 0 4 radius -20 aperture 8' 'sphere detect center 0 0 0 radius 50' \
        'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 12' 'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 5 pol 1 2 0' \
        'output polar tab.csv' 'output summary tab.sum' > new/tab.scene &&
    cp new/* old/ || return 1
    for s in singlet.scene prism.scene pn.scene ph.scene p17.scene lin.scene tab.scene; do
        trace_in "$BIN" "$d/new" $s && trace_in "$MAINBIN" "$d/old" $s || { echo "$s failed"; return 1; }
    done
    n=0
    for f in singlet-hits.csv prism-hits.csv prism-hits.npy prism-all.h5 prism-17.csv lin.csv prism.l \
             tab.csv tab.sum; do
        cmp "new/$f" "old/$f" || return 1; n=$((n + 1))
    done
    head -1 new/singlet-hits.csv | grep -qx 'ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,length,opl' || return 1
    echo "$n files byte-identical to $MAINBIN's"
)
# without polarization the hits keep exactly their columns, no S0..S3 (the singlet's
# and the prism's headers as the tracer wrote them before the Stokes columns)
stokes_cols() (
    d=$SW/cols; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    cp "$TOP/scenes/singlet.scene" "$TOP/scenes/prism.scene" "$TOP/scenes/prism.obj" . &&
    trace_in "$BIN" "$d" singlet.scene && trace_in "$BIN" "$d" prism.scene || return 1
    head -1 singlet-hits.csv | grep -qx 'ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,length,opl' &&
        ! head -1 prism-hits.csv | grep -q 'S0' && head -1 prism-hits.csv | grep -q '^ray,depth,'
)
check "no polarization: the hits files have no S0..S3 columns (the singlet's header as before)" stokes_cols
if [ -n "$MAINBIN" ] && [ -x "$MAINBIN" ] && [ "$(cd "$SW" && printf 'scene\n%s/scenes/singlet.scene\nn\n' "$TOP" > m.in &&
        "$MAINBIN" --trace -i m.in m.rec > /dev/null 2>&1 && echo ok)" = ok ]; then
    check "no polarization: hits (CSV, .npy, HDF5, csv17) and segments byte-identical to the main build's; a polar table too" stokes_same
else
    echo "SKIP t_41: LENSMAT_MAIN (a build from before a change) not given: the byte comparison was not made"
fi

# partially polarized sources, `pol stokes S1 S2 S3` (over S0): what a detector right
# behind the source reports is the vector given (a ray along z, a cone about z with
# `polarization ref 0 1 0`: the frame's rule), the degree of polarization its length;
# through a polarizer at 30 deg, a quarter-wave plate at 45 deg and a 60-degree
# retarder at 10 deg, S = M3 M2 M1 S (Mueller, 1e-12); `pol stokes 0 0 0` is the
# unpolarized source's hits to the bits
stokes_partial() (
    d=$SW/part; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    printf '%s\n' 'plane detect at 0 0 3 normal 0 0 1 disc 5' 'polarization on ref 0 1 0' \
        'source ray from 0 0 0 dir 0 0 1 pol stokes 0.3 -0.4 0.5' \
        'source cone from 0 0 0 dir 0 0 1 angle 10 rings 3 pol stokes 0.3 -0.4 0.5' \
        'output hits h.csv' > s.scene &&
    printf '%s\n' 'plane refract 1 1 polarizer 0.86602540378443865 0.5 0 at 0 0 1 normal 0 0 1 disc 5' \
        'plane refract 1 1 qwp 0.70710678118654752 0.70710678118654752 0 at 0 0 2 normal 0 0 1 disc 5' \
        'plane refract 1 1 retarder 0.98480775301220806 0.17364817766693035 0 60 at 0 0 3 normal 0 0 1 disc 5' \
        'plane detect at 0 0 4 normal 0 0 1 disc 5' \
        'source ray from 0 0 0 dir 0 0 1 pol stokes -0.2 0.1 0.6' 'output hits m.csv' > m.scene &&
    printf '%s\n' 'cap refract 1 1.5 vertex 0 0 1 radius 20 aperture 6' 'plane detect at 0 0 8 normal 0 0 1 disc 20' \
        'source cone from 0 0 0 dir 0 0 1 angle 15 rings 4 pol stokes 0 0 0' 'output hits u.csv' \
        'polarization on' > u.scene &&
    sed 's/ pol stokes 0 0 0//; s/u.csv/v.csv/' u.scene > v.scene &&
    for f in s m u v; do trace_in "$BIN" "$d" $f.scene || return 1; done
    awk "$MUELLER"'NR > 1 { s[0] = 1; s[1] = .3; s[2] = -.4; s[3] = .5
        for (k = 0; k < 4; k++) o[k] = s[k] * $col["S0"]; e = off(o); n++
        dop = sqrt($col["S1"] ^ 2 + $col["S2"] ^ 2 + $col["S3"] ^ 2) / $col["S0"]
        if (e > 1e-12 || ab(dop - sqrt(.5)) > 1e-12) { bad = 1; print "row " NR ": worst " e ", DoP " dop } }
        END { printf "%d hits at the source: S/S0 = (0.3, -0.4, 0.5), DoP %.15f\n", n, dop
              exit !(n > 30 && !bad) }' h.csv &&
    awk "$MUELLER"'NR == 2 { s[0] = 1; s[1] = -.2; s[2] = .1; s[3] = .6
        pol_m(30 * deg, M1); ret_m(45 * deg, pi / 2, M2); ret_m(10 * deg, 60 * deg, M3)
        mv(M1, s, a); mv(M2, a, b); mv(M3, b, o); e = off(o)
        printf "polarizer, qwp, retarder: S = %s %s %s %s, Mueller %.9f %.9f %.9f %.9f, worst %.2g\n",
            $col["S0"], $col["S1"], $col["S2"], $col["S3"], o[0], o[1], o[2], o[3], e; n++
        if (e > 1e-12) bad = 1 } END { exit !(n == 1 && !bad) }' m.csv &&
    cmp u.csv v.csv && echo "pol stokes 0 0 0 through a singlet: $(($(wc -l < u.csv) - 1)) hits, the unpolarized source's bytes"
)
check "pol stokes (partially polarized): S/S0 and DoP as given at the source (two frames), Mueller through a polarizer, qwp and retarder (1e-12), 0 0 0 = unpolarized" \
    stokes_partial

# Refusals, each at its FILE:LINE (exit 2 in a replay)
stokes_bad() (
    d=$SW/bad; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    one() {   # POL-VALUE WANT
        printf '%s\n' 'plane detect at 0 0 3 normal 0 0 1 disc 5' "source ray from 0 0 0 dir 0 0 1 pol $1" > bad.scene
        printf 'scene\nbad.scene\n' > bad.in
        "$BIN" --trace -i bad.in bad.rec > /dev/null 2> bad.err; rc=$?
        [ "$rc" = 2 ] && grep -q "$2" bad.err || { echo "pol $1: want: $2"; cat bad.err; return 1; }
    }
    one 'ellipse 10 50' "bad.scene:2: source ray: 'pol ellipse': the ellipticity angle 50 must lie in \[-45, 45\]" &&
    one 'ellipse 10 -45.5' "bad.scene:2: .*the ellipticity angle -45.5 must lie" &&
    one 'ellipse 10' "bad.scene:2: source ray: 'pol' expects X Y Z (linear), right or left" &&
    one 'ellipse 10 x' "bad.scene:2: source ray: 'pol': 'x' is not a number" &&
    one 'jones -1 1 0 0' "bad.scene:2: source ray: 'pol jones': the amplitudes -1 1 must be at least 0" &&
    one 'jones 0 0 0 0' "bad.scene:2: source ray: 'pol jones': the amplitudes 0 0 must be" &&
    one 'jones 1 1 0 nan' "bad.scene:2: source ray: 'pol': 'nan': NaN is not a number" &&
    one 'jones 1 1 0' "bad.scene:2: source ray: 'pol' expects" &&
    one 'circular' "bad.scene:2: source ray: 'pol' expects" &&
    one 'right left' "bad.scene:2: source ray: 'pol' expects" &&
    one '1 0' "bad.scene:2: source ray: 'pol' expects" &&
    one '0 0 0' "bad.scene:2: source ray: 'pol' 0 0 0 is a zero-length direction" &&
    one 'right pol left' "bad.scene:2: source ray: 'pol' given twice" &&
    one 'stokes 0.8 0.6 0.1' "bad.scene:2: source ray: 'pol stokes' 0.8 0.6 0.1: the degree of polarization sqrt(S1^2 + S2^2 + S3^2) = 1.00499 is more than 1" &&
    one 'stokes 0.5 0.5' "bad.scene:2: source ray: 'pol' expects" &&
    one 'stokes 0 nan 0' "bad.scene:2: source ray: 'pol': 'nan': NaN is not a number"
)
check "bad pol values refused at FILE:LINE (ellipticity beyond 45, negative or zero amplitudes, NaN, unknown words, short lists)" \
    stokes_bad
