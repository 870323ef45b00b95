# t_98_polar.sh -- polarization ray tracing (src/trace/tr_polar.c, scene_polar.c,
# scene_polout.c): the engine against closed forms written in its C test (t_polar:
# Fresnel rs rp ts tp read off traced PRT matrices, a Fresnel rhomb's retardance,
# Malus, wave plates, a quarter-wave coating), and scene files through `lensmat
# --trace`: the rhomb of scenes/rhomb.scene against the TIR closed form computed here
# in awk and Born & Wolf's published 45 degrees a reflection (Principles of Optics,
# 1.5.4: n = 1.51, 54 deg 37'), Malus's law through two traced polarizers, a
# quarter-wave plate making circular light, a coated surface's Rs and Rp at three
# wavelengths equal to the --polar film calculator's, an unpolarized singlet with
# polarization on giving the same hits, the .npy table, the refusals, exact replay.

cd "$TOP" || return 1
unit "$TOP/build/obj/trace_tests/t_polar"
unit "$TOP/build/asan/trace_tests/t_polar"

PW=$WORK/polar
mkdir -p "$PW"

# col FILE NAME: the column number of NAME in a CSV's header
col() { head -1 "$1" | tr ',' '\n' | grep -nx "$2" | cut -d: -f1; }

# trace_scene BIN DIR SCENE: trace the scene in DIR (answers recorded in DIR/t.rec)
trace_scene() (
    cd "$2" && printf 'scene\n%s\nn\n' "$3" > t.in && "$1" --trace -i t.in t.rec > t.out 2> t.err
)

polar_rhomb() (
    d=$PW/rhomb; rm -rf "$d"; mkdir -p "$d"; cp "$TOP/scenes/rhomb.scene" "$d/" &&
    trace_scene "$1" "$d" rhomb.scene && cd "$d" || return 1
    grep -q 'Written: rhomb-polar.csv (Stokes parameters' t.out || return 1
    r=$(col rhomb-polar.csv retardance_deg) s0=$(col rhomb-polar.csv S0) s3=$(col rhomb-polar.csv S3)
    [ "$(wc -l < rhomb-polar.csv)" = 2 ] || return 1
    # tan(delta/2) = cos t sqrt(sin^2 t - m^2) / sin^2 t, m = 1/1.51, two reflections
    awk -F, -v r="$r" -v a="$s0" -v v="$s3" 'NR == 2 {
        pi = atan2(0, -1); t = 54.6 * pi / 180; m = 1 / 1.51; s2 = sin(t) ^ 2
        x = cos(t) * sqrt(s2 - m * m) / s2; one = 2 * atan2(x, 1) * 180 / pi
        printf "traced %.12f deg, closed form 2 x %.12f, circular |V|/I %.9f\n", $r, one, -$v / $a
        d = $r - 2 * one; if (d < 0) d = -d
        e = $r - 90; if (e < 0) e = -e
        exit !(d < 1e-9 && e < 0.05 && -$v / $a > 0.99999) }' rhomb-polar.csv || return 1
    # the record replays to the same record and the same table
    cp rhomb-polar.csv first.csv && grep '^input:' t.rec | sed 's/^input: //' > re.in &&
        "$1" --trace r2.rec < re.in > /dev/null 2>&1 && cmp t.rec r2.rec && cmp first.csv rhomb-polar.csv
)
check "rhomb.scene: traced retardance = 2 x the TIR closed form (1e-9 deg), Born & Wolf's 90 deg to 0.05, circular out; replays exactly" \
    polar_rhomb "$BIN"
check "rhomb.scene under ASan/UBSan" polar_rhomb "$ASAN"

# Malus: two polarizers 30 degrees apart in an unpolarized beam: 0.5 cos^2 30 = 0.375
polar_malus() (
    d=$PW/malus; rm -rf "$d"; mkdir -p "$d" && cd "$d" &&
    cat > m.scene <<'EOF' &&
plane refract 1 1 polarizer 1 0 0 at 0 0 1 normal 0 0 1 disc 5
plane refract 1 1 polarizer 0.866025403784439 0.5 0 at 0 0 2 normal 0 0 1 disc 5
plane detect at 0 0 3 normal 0 0 1 disc 5
source collimated from 0 0 0 dir 0 0 1 radius 1 grid 7
output polar m.csv
output summary m.sum
EOF
    trace_scene "$BIN" "$d" m.scene || return 1
    s0=$(col m.csv S0) s1=$(col m.csv S1) s2=$(col m.csv S2)
    awk -F, -v a="$s0" -v b="$s1" -v c="$s2" 'NR > 1 { t += $a; q += $b; u += $c; n++ }
        END { w = 0.375; printf "%d rays: S0 %.17g (want %.17g), S1/S0 %.15f, S2/S0 %.15f\n", n, t, w, q / t, u / t
              e = t - w; if (e < 0) e = -e
              exit !(n > 20 && e < 1e-14 && (q / t - 0.5) ^ 2 < 1e-28 && (u / t - 0.8660254037844386) ^ 2 < 1e-28) }' m.csv &&
    awk '$1 == "detected" { d = $2 } $1 == "absorbed" { a = $2 }
         END { exit !((d - 0.375) ^ 2 < 1e-28 && (a - 0.625) ^ 2 < 1e-28) }' m.sum
)
check "Malus's law through two traced polarizers (scene file): 0.375 detected, 0.625 absorbed, light along the second's axis" polar_malus

# the table does not depend on the thread count (a cone through the rhomb's glass with
# reflections followed: many small batches)
polar_threads() (
    d=$PW/thr; rm -rf "$d"; mkdir -p "$d" && cd "$d" &&
    printf '%s\n' 'cap refract 1 1.5 coating c vertex 0 0 0 radius 20 aperture 8' \
        'coating c layer 1.38 100 layer 2.0 70' 'cap refract 1.5 1 retarder 1 1 0 30 vertex 0 0 4 radius -20 aperture 8' \
        'sphere detect center 0 0 0 radius 50' 'source cone from 0 0 -10 dir 0 0 1 angle 20 rings 30' \
        'threads 1' 'batch' 'output polar one.csv' | grep -v '^batch' > one.scene &&
    sed 's/^threads 1/threads 2/; s/one.csv/two.csv/' one.scene > two.scene &&
    trace_scene "$BIN" "$d" one.scene && trace_scene "$BIN" "$d" two.scene || return 1
    [ "$(wc -l < one.csv)" -gt 2000 ] && cmp one.csv two.csv
)
check "the polar table is the same on one thread and two (coated, retarding lens, reflections followed)" polar_threads

# the proper retardance is the path's, not the frames': a tilted, coated singlet whose
# rays (reflections followed) leave in many directions, traced with three Stokes
# references (an unpolarized source: the same light in every frame); the retardance
# column is the same for each ray to 1e-9 deg while S1 (frame-bound) changes
polar_proper() (
    d=$PW/proper; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    for r in "1 0 0" "0 1 0" "0.3 -0.8 0.5"; do
        printf '%s\n' 'cap refract 1 1.7 coating c vertex 0 0 0 radius 20 aperture 6' \
            'coating c layer 1.38 100' 'cap refract 1.7 1 vertex 0 0 4 radius -20 aperture 6' \
            'sphere detect center 0 0 0 radius 40' \
            'source cone from 3 2 -10 dir -0.2 -0.1 1 angle 12 rings 6' \
            "polarization on ref $r" "output polar p.csv" > p.scene
        trace_scene "$BIN" "$d" p.scene && mv p.csv "p-$(echo "$r" | tr ' ' _).csv" || return 1
    done
    [ "$(wc -l < p-1_0_0.csv)" -gt 300 ] || return 1
    paste -d, p-1_0_0.csv p-0_1_0.csv p-0.3_-0.8_0.5.csv | awk -F, 'NR == 1 {
            for (i = 1; i <= NF; i++) if (!($i in c)) c[$i] = i; w = NF / 3; next }
        { r = c["retardance_deg"]; s = c["S1"]; n++; if ($r > 1 && $r < 179) mid++
          for (k = 1; k < 3; k++) { e = $(r + k * w) - $r; if (e < 0) e = -e; if (e > m) m = e
              f = $(s + k * w) / $(c["S0"] + k * w) - $s / $c["S0"]; if (f < 0) f = -f; if (f > ds) ds = f
              if ($(c["ray"] + k * w) != $c["ray"] || $(c["depth"] + k * w) != $c["depth"]) bad++ } }
        END { printf "%d hits (%d with 1..179 deg): retardance differs by at most %.2g deg across references; S1/S0 by up to %.3g\n", n, mid, m, ds
              exit !(n > 300 && !bad && mid > 50 && m < 1e-9 && ds > 1e-3) }'
)
check "the proper retardance does not depend on the Stokes reference (3 references, 1e-9 deg) while S1 does: a tilted coated singlet, reflections followed" polar_proper

# a quarter-wave plate, fast axis x, 45-degree light: circular (V = 1, the --polar
# calculator's "qwp 0" on its 45-degree input); a half-wave plate: -45 degrees
polar_qwp() (
    d=$PW/qwp; rm -rf "$d"; mkdir -p "$d" && cd "$d" &&
    printf '%s\n' 'plane refract 1 1 qwp 1 0 0 at 0 0 1 normal 0 0 1 disc 5' \
        'plane detect at 0 0 3 normal 0 0 1 disc 5' 'source ray from 0 0 0 dir 0 0 1 pol 1 1 0' \
        'output polar q.csv' > q.scene &&
    sed 's/ qwp / hwp /; s/q.csv/h.csv/' q.scene > h.scene &&
    trace_scene "$BIN" "$d" q.scene && trace_scene "$BIN" "$d" h.scene || return 1
    v=$(col q.csv S3) s2=$(col h.csv S2)
    awk -F, -v v="$v" 'NR == 2 { printf "qwp: V = %.17g\n", $v; exit !(($v - 1) ^ 2 < 1e-28) }' q.csv &&
    awk -F, -v v="$s2" 'NR == 2 { printf "hwp: S2 = %.17g\n", $v; exit !(($v + 1) ^ 2 < 1e-28) }' h.csv
)
check "a traced quarter-wave plate makes circular light (V = 1), a half-wave plate turns 45 deg to -45" polar_qwp

# A quarter-wave MgF2 layer (1.38, 99.6377 nm: a quarter wave at 550 nm) on N-BK7's
# 1.5168, s- and p-polarized rays at 30 degrees, 450 550 650 nm: the reflected ray's
# S0 against `lensmat --polar`'s film calculator (its 6 printed digits)
polar_coating() (
    d=$PW/coat; rm -rf "$d"; mkdir -p "$d" && cd "$d" &&
    cat > c.scene <<'EOF' &&
coating mgf2 layer 1.38 99.6376811594203
plane refract 1 1.5168 coating mgf2 at 0 0 0 normal 0 0 1 disc 10
plane detect at 0 0 -5 normal 0 0 1 disc 100
plane detect at 0 0 5 normal 0 0 1 disc 100
source ray from -0.577350269189626 0 -1 dir 0.5 0 0.866025403784439 pol 0 1 0 lambda 450 550 650
source ray from -0.577350269189626 0 -1 dir 0.5 0 0.866025403784439 pol 0.866025403784439 0 -0.5 lambda 450 550 650
output polar c.csv
EOF
    trace_scene "$BIN" "$d" c.scene || return 1
    printf 'film\n1\n1.5168\n550\n1\n1.38\n0\n30\n' | "$BIN" --polar f.rec > f.out 2>&1 || return 1
    z=$(col c.csv z) s0=$(col c.csv S0) l=$(col c.csv lambda_nm) r=$(col c.csv ray)
    # rows of reflected rays: "nm s|p R%"
    awk -F, -v z="$z" -v a="$s0" -v l="$l" -v r="$r" 'NR > 1 && $z < 0 {
        printf "%.1f %s %.17g\n", $l, ($r % 2 ? "p" : "s"), 100 * $a }' c.csv > traced &&
    for nm in 450.0 550.0 650.0; do
        grep "^ *$nm nm: Rs" f.out | head -1 |
            sed 's/.*Rs \([0-9.e-]*\)%, Rp \([0-9.e-]*\)%.*/\1 \2/' |
            awk -v nm="$nm" '{ print nm, "s", $1; print nm, "p", $2 }'
    done > calc && [ "$(wc -l < calc)" = 6 ] && [ "$(wc -l < traced)" = 6 ] || return 1
    awk '{ print $1 "-" $2, $3 }' traced | sort > t.s && awk '{ print $1 "-" $2, $3 }' calc |
        sort > c.s && join t.s c.s > both || return 1
    cat both
    awk '{ e = ($2 - $3) / $3; if (e < 0) e = -e; if (e > m) m = e; n++ }
         END { printf "worst relative difference %.2g (6 digits printed)\n", m; exit !(n == 6 && m < 5e-6) }' both
)
check "a traced MgF2-coated surface: Rs, Rp at 30 deg and 450/550/650 nm = the --polar film calculator's" \
    polar_coating

# An unpolarized singlet with `polarization on`: the same hits (points, directions,
# rays, depths) and s, p powers within 1e-12 of the run without
polar_same() (
    d=$PW/same; rm -rf "$d"; mkdir -p "$d" && cd "$d" && cp "$TOP/scenes/singlet.scene" a.scene &&
    { cat a.scene; echo 'polarization on'; } | sed 's/singlet-hits.csv/b-hits.csv/; s/singlet.sum/b.sum/' > b.scene &&
    trace_scene "$BIN" "$d" a.scene && trace_scene "$BIN" "$d" b.scene || return 1
    grep -q 'Sequential lens.*kernel scalar' t.out || { echo "not ray by ray"; return 1; }
    [ "$(wc -l < singlet-hits.csv)" = "$(wc -l < b-hits.csv)" ] || return 1
    paste -d, singlet-hits.csv b-hits.csv | awk -F, 'NR > 1 {
        for (i = 1; i <= 10; i++) if ($i != $(i + 15)) bad++
        for (i = 11; i <= 13; i++) { e = $i - $(i + 15); if (e < 0) e = -e; if (e > 1e-12 * $13) bad++ } n++ }
        END { printf "%d hits, %d differences\n", n, bad; exit !(n > 100 && bad == 0) }'
)
check "singlet.scene with polarization on: the same hits, s and p powers within 1e-12" polar_same

# The table as .npy (NumPy reads it; one row per hit; the columns' names)
polar_npy() (
    d=$PW/npy; rm -rf "$d"; mkdir -p "$d" && cd "$d" && sed 's/rhomb-polar.csv/rp.npy/' \
        "$TOP/scenes/rhomb.scene" > r.scene && trace_scene "$BIN" "$d" r.scene || return 1
    grep -q 'Written: rp.npy (Stokes parameters and PRT matrix of every hit, NumPy .npy)' t.out &&
    /usr/bin/python3 -c "
import numpy, sys
a = numpy.load('rp.npy')
assert a.shape == (1,) and a.dtype.names[:7] == ('ray', 'depth', 'surface', 'x', 'y', 'z', 'S0'), a.dtype
assert abs(a['retardance_deg'][0] - 90.0242) < 1e-3 and a['P33_im'].dtype == numpy.float64
print('npy ok', a['S0'][0], a['S3'][0])"
)
check "output polar FILE.npy: NumPy reads the table (fields named, one row per hit)" polar_npy

# Refusals, each with the scene's FILE:LINE (exit 2 in a replay)
polar_bad() (
    d=$PW/bad; rm -rf "$d"; mkdir -p "$d" && cd "$d" || return 1
    one() {   # SCENE-TEXT WANT
        printf '%s\n' "$1" 'source ray from 0 0 -1 dir 0 0 1' > bad.scene
        printf 'scene\nbad.scene\n' > bad.in
        "$BIN" --trace -i bad.in bad.rec > /dev/null 2> bad.err; rc=$?
        [ "$rc" = 2 ] && grep -q "$2" bad.err || { echo "want: $2"; cat bad.err; return 1; }
    }
    one 'plane refract 1 1.5 coating ar at 0 0 0 normal 0 0 1 disc 1' 'bad.scene:1: coating ar: no such coating' &&
    one 'plane mirror polarizer 1 0 0 at 0 0 0 normal 0 0 1 disc 1' 'bad.scene:1: plane: polarizer, retarder, qwp, hwp and coating go on a refracting' &&
    one 'plane refract 1 1 polarizer 0 0 0 at 0 0 0 normal 0 0 1 disc 1' "bad.scene:1: plane: a polarizer's or retarder's axis must not be zero" &&
    one 'plane refract 1 1 qwp 1 0 0 hwp 1 0 0 at 0 0 0 normal 0 0 1 disc 1' 'bad.scene:1: plane: give one of polarizer' &&
    one 'coating x layer 1.38' "bad.scene:1: coating: expected 'coating NAME layer N D" &&
    one 'coating x layer -1 100' 'bad.scene:1: coating x: layer 1: the index must be positive' &&
    one 'output polar p.csv h5' "bad.scene:1: output polar: 'h5' is not a format" &&
    one 'polarization maybe' 'bad.scene:1: polarization: expected' &&
    printf '%s\n' 'polarization off' 'plane refract 1 1 qwp 1 0 0 at 0 0 0 normal 0 0 1 disc 1' > x &&
    one "$(cat x)" 'bad.scene: `polarization off`, but the scene has a polarizer'
)
check "refused with FILE:LINE: an unknown coating, elements off refracting surfaces, zero axes, two elements, bad layers and formats" polar_bad
