# t_63_wavelength.sh -- the tracer per wavelength (issue 14): scene files that name
# glasses for their media and wavelengths for their sources.  The expected values are
# computed here, independently of the program: the indices with awk from the Sellmeier
# coefficients of data/glass.txt, the absorption from its transmittance tables, and
# the angles from Snell's law.  Also: the wavelength column appears only when a scene
# names wavelengths, and the example scenes keep the bytes they had before (checksums
# in golden/trace/scenes.sha256, made by the tracer before wavelengths existed).

cd "$TOP" || return 1   # (a group before may have left the cwd elsewhere; the test
                          #  binaries name their module relative to the top)
# the engine's side: Beer-Lambert and every ray's lambda through its table (both builds)
unit "$TOP/build/obj/trace_tests/t_absorb"
unit "$TOP/build/asan/trace_tests/t_absorb"

WW=$WORK/wavelength
mkdir -p "$WW"
GLASS=$TOP/data/glass.txt

# sellmeier NAME UM: the index from the catalogue's coefficients (awk, not lensmat)
sellmeier() {
    awk -v g="$1" -v l="$2" '$1 == g && ($2 == "sellmeier" || $2 == "sellmeier-l") {
        n2 = 1; l2 = l * l
        for (i = 7; i < NF; i += 2) { c = $(i + 1); if ($2 == "sellmeier-l") c = c * c
                                      n2 += $i * l2 / (l2 - c) }
        printf "%.17g\n", sqrt(n2); found = 1 }
        END { exit !found }' "$GLASS"
}

# alpha NAME UM: -ln(t)/d, ln t linear in lambda between the tau points (awk)
alpha() {
    awk -v g="$1" -v l="$2" '$1 == g && $2 == "tau" {
        d = $3
        for (i = 4; i + 3 <= NF; i += 2)
            if (l >= $i && l <= $(i + 2)) {
                u = (l - $i) / ($(i + 2) - $i); a = -log($(i + 1)); b = -log($(i + 3))
                printf "%.17g\n", (a + u * (b - a)) / d; found = 1; exit }
        }
        END { exit !found }' "$GLASS"
}

# wl_trace NAME SCENE-TEXT: trace it in $WW/NAME (scene s.scene, outputs h.csv s.sum)
wl_trace() {
    wd=$WW/$1; rm -rf "$wd"; mkdir -p "$wd"
    printf '%s\n' "$2" > "$wd/s.scene"
    trace_session "$BIN" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
}

# A prism: normal entry at z = 0, exit face tilted by the apex angle A = 30 degrees,
# so the ray inside meets it at A and leaves at asin(n sin A): deviation
# asin(n sin A) - A.  One ray per wavelength, the deviation read from the hit's
# direction, against Snell's law with the awk indices, to 1e-12 rad.
PRISM_A=30
prism_scene() {   # GLASS LAMBDAS
    printf '%s\n' \
        "plane refract 1 $1 at 0 0 0 normal 0 0 1 disc 8" \
        "plane refract $1 1 at 0 0 10 normal 0 -0.5 0.8660254037844386 disc 8" \
        "plane detect at 0 0 60 normal 0 0 1 rect 400 400" \
        "source ray from 0 0 -5 dir 0 0 1 lambda $2" \
        "reflections off" \
        "output hits h.csv" "output summary s.sum"
}
# deviation_check GLASS NM UM: row of $wd/h.csv with lambda_nm NM against Snell at UM
deviation_check() {
    wn=$(sellmeier "$1" "$3") || { echo "no index for $1"; return 1; }
    awk -F, -v nm="$2" -v n="$wn" -v A="$PRISM_A" 'NR > 1 && $16 == nm {
        pi = atan2(0, -1); a = A * pi / 180; s = n * sin(a)
        want = atan2(s, sqrt(1 - s * s)) - a
        got = atan2(sqrt($9 * $9 + $8 * $8), $10)
        e = got - want; if (e < 0) e = -e
        printf "%s at %s nm: n %.9f, deviation %.12f rad, Snell %.12f, error %.2g\n",
               g, nm, n, got, want, e
        if (e > 1e-12) bad = 1; found = 1 }
        END { exit bad || !found }' g="$1" "$wd/h.csv"
}
prism_fdc() {
    wg=$1
    wl_trace "prism_$wg" "$(prism_scene "$wg" "F d C")" || return 1
    wd=$WW/prism_$wg
    deviation_check "$wg" 486.1327 0.4861327 && deviation_check "$wg" 587.5618 0.5875618 &&
        deviation_check "$wg" 656.2725 0.6562725 || return 1
    # dispersion: the F ray is bent more than the C ray
    awk -F, 'NR > 1 { dev[$16] = atan2(sqrt($9 * $9 + $8 * $8), $10) }
             END { exit !(dev["486.1327"] > dev["587.5618"] && dev["587.5618"] > dev["656.2725"]) }' \
        "$wd/h.csv"
}
check "wavelength: an N-BK7 prism deviates F, d, C as Snell's law with the catalogue's indices" prism_fdc N-BK7
check "wavelength: an N-SF6 prism at F, d, C (Sellmeier, flint)" prism_fdc N-SF6
check "wavelength: a fused-silica prism at F, d, C (Malitson's resonance form)" prism_fdc F_SILICA

# The rays are numbered on from one wavelength to the next; the column is in nm.
wl_numbering() {
    wd=$WW/prism_N-BK7
    awk -F, 'NR == 1 { exit $16 != "lambda_nm" || NF != 16 }' "$wd/h.csv" &&
        [ "$(cut -d, -f1 "$wd/h.csv" | tail -n +2 | tr '\n' ' ')" = "0 1 2 " ] &&
        [ "$(grep -c '^wavelength_nm ' "$wd/s.sum")" -eq 3 ] &&
        grep -q '^rays 3$' "$wd/s.sum"
}
check "wavelength: hits carry lambda_nm, rays numbered across wavelengths, summary per wavelength" wl_numbering

# An absorbing slab at normal incidence, reflections off: detected = (1 - R)^2 exp(-alpha L),
# R = ((n-1)/(n+1))^2.  At 334 nm N-BK7's 25 mm table gives t = 0.780 exactly.
slab_scene() {   # THICKNESS LAMBDA [reflections]
    printf '%s\n' \
        "plane refract 1 N-BK7 at 0 0 0 normal 0 0 1 disc 20" \
        "plane refract N-BK7 1 at 0 0 $1 normal 0 0 1 disc 20" \
        "plane detect at 0 0 100 normal 0 0 1 disc 50" \
        "source ray from 0 0 -5 dir 0 0 1 lambda $2" \
        "reflections ${3:-off}" "cutoff 0" \
        "output hits h.csv" "output summary s.sum"
}
slab_check() {   # NAME THICKNESS NM UM REFLECTIONS
    wl_trace "$1" "$(slab_scene "$2" "$3" "$5")" || return 1
    wd=$WW/$1
    wn=$(sellmeier N-BK7 "$4") && wa=$(alpha N-BK7 "$4") || { echo "no data"; return 1; }
    awk -v n="$wn" -v a="$wa" -v L="$2" -v refl="$5" '$1 == "detected" { got = $2 }
        $1 == "absorbed" { abs = $2 } $1 == "balance_error" { bal = $2 }
        END { R = ((n - 1) / (n + 1)) ^ 2; t = exp(-a * L)
              want = (1 - R) ^ 2 * t
              if (refl == "on") want = want / (1 - R * R * t * t)   # the internal echoes
              e = (got - want) / want; if (e < 0) e = -e
              printf "L %s: n %.9f alpha %.6g/mm: detected %.15g, expected %.15g (%.2g); absorbed %.6g; balance %s\n",
                     L, n, a, got, want, e, abs, bal
              exit !(e < 1e-12 && abs > 0 && (bal == 0 || bal ~ /e-1[5-9]/)) }' "$wd/s.sum"
}
check "wavelength: a 25 mm N-BK7 slab at 334 nm transmits 0.780 x Fresnel (its table's point)" \
    slab_check slab25 25 334 0.334 off
check "wavelength: a 10 mm slab at 334 nm transmits 0.780^(10/25) x Fresnel" \
    slab_check slab10 10 334 0.334 off
check "wavelength: between table points (342 nm) ln t is interpolated linearly" \
    slab_check slab342 25 342 0.342 off
check "wavelength: with reflections on, the echoes inside the slab lose exp(-2 alpha L) each" \
    slab_check slabecho 25 334 0.334 on
# A slab of a medium without transmittance data (diamond) absorbs nothing.
wl_clear() {
    wl_trace clear "plane refract 1 DIAMOND at 0 0 0 normal 0 0 1 disc 20
plane refract DIAMOND 1 at 0 0 25 normal 0 0 1 disc 20
plane detect at 0 0 100 normal 0 0 1 disc 50
source ray from 0 0 -5 dir 0 0 1 lambda 400
output summary s.sum" && grep -q '^absorbed 0$' "$WW/clear/s.sum"
}
check "wavelength: a medium without transmittance data absorbs nothing" wl_clear

# A metre of water at 632.8 nm: its absorption from Hale & Querry's extinction
# coefficient (alpha = 4 pi k / lambda, linear between their points), here in awk.
wl_water() {
    wl_trace water "plane refract 1 water at 0 0 0 normal 0 0 1 disc 20
plane refract water 1 at 0 0 1000 normal 0 0 1 disc 20
plane detect at 0 0 1100 normal 0 0 1 disc 50
source ray from 0 0 -5 dir 0 0 1 lambda 632.8
reflections off
output summary s.sum" || return 1
    wn=$(sellmeier WATER 0.6328) || return 1
    wa=$(awk -v l=0.6328 '$1 == "WATER" && $2 == "k" {
        for (i = 3; i + 3 <= NF; i += 2) if (l >= $i && l <= $(i + 2)) {
            pi = atan2(0, -1); a = 4 * pi * $(i + 1) / ($i * 1e-3)
            b = 4 * pi * $(i + 3) / ($(i + 2) * 1e-3); u = (l - $i) / ($(i + 2) - $i)
            printf "%.17g\n", a + u * (b - a); exit } }' "$GLASS")
    awk -v n="$wn" -v a="$wa" '$1 == "detected" { got = $2 }
        END { R = ((n - 1) / (n + 1)) ^ 2; want = (1 - R) ^ 2 * exp(-a * 1000)
              e = (got - want) / want; if (e < 0) e = -e
              printf "alpha %.5g /m: detected %.15g, expected %.15g\n", a * 1e3, got, want
              exit !(e < 1e-12 && want < 0.75) }' "$WW/water/s.sum"
}
check "wavelength: a metre of water at 632.8 nm absorbs as Hale & Querry's k says" wl_water

# The cornea rig's laser: a He-Ne Gaussian beam (632.8 nm) through an N-BK7 prism uses
# n(632.8 nm), not n(d): its axial ray's deviation is Snell's with n(0.6328), and differs
# from the d line's by more than 1e-5 rad.
rig_laser() {
    wl_trace laser "$(printf '%s\n' \
        "plane refract 1 glass N-BK7 at 0 0 0 normal 0 0 1 disc 8" \
        "plane refract glass N-BK7 1 at 0 0 10 normal 0 -0.5 0.8660254037844386 disc 8" \
        "plane detect at 0 0 60 normal 0 0 1 rect 400 400" \
        "source gaussian from 0 0 -5 dir 0 0 1 waist 0.5 wavelength 0.0006328 rings 1 lambda hene" \
        "output hits h.csv")" || return 1
    wd=$WW/laser
    awk -F, 'NR == 1 || $1 == 0' "$wd/h.csv" > "$wd/h0" && mv "$wd/h0" "$wd/h.csv"  # the axial ray
    deviation_check N-BK7 632.8 0.6328 || return 1
    wnd=$(sellmeier N-BK7 0.5875618)
    awk -F, -v n="$wnd" 'NR > 1 { pi = atan2(0, -1); a = pi / 6; s = n * sin(a)
        dd = atan2(s, sqrt(1 - s * s)) - a; got = atan2(sqrt($9 * $9 + $8 * $8), $10)
        exit !(dd - got > 1e-5) }' "$wd/h.csv"
}
check "wavelength: the rig's laser at 632.8 nm (lambda hene) uses n(632.8) for N-BK7" rig_laser

# A source naming no wavelength in a scene that names some is at the d line; a glass
# named without any wavelength in the scene is at d too, with no wavelength column.
wl_default() {
    wl_trace dflt "$(prism_scene N-BK7 d | sed 's/ lambda d//')" || return 1
    wd=$WW/dflt
    head -1 "$wd/h.csv" | grep -qx 'ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,length,opl' &&
        ! grep -q '^wavelength_nm' "$wd/s.sum" || return 1
    # same direction as the d ray of the F d C trace, to the bit
    wa=$(awk -F, 'NR == 2 { print $8, $9, $10 }' "$wd/h.csv")
    wb=$(awk -F, 'NR > 1 && $16 == "587.5618" { print $8, $9, $10 }' "$WW/prism_N-BK7/h.csv")
    [ -n "$wa" ] && [ "$wa" = "$wb" ]
}
check "wavelength: glasses without a named wavelength are at d, and no column is added" wl_default

# Segments carry the wavelength as a fourth column when the scene names some.
wl_segments() {
    wl_trace seg "$(prism_scene N-BK7 'C 632.8' | sed 's/^output hits h.csv$/output segments s.l/')" &&
        awk 'NF != 4 { exit 1 } { w[$4] = 1 } END { exit !(("656.2725" in w) && ("632.8" in w)) }' \
            "$WW/seg/s.l"
}
check "wavelength: segments (p.l) carry lambda as a fourth column when wavelengths are named" wl_segments

# Refusals, with the scene's file and line.
wl_bad() {   # NAME EXPECTED-TEXT SCENE
    wd=$WW/bad_$1; rm -rf "$wd"; mkdir -p "$wd"
    printf '%s\n' "$3" > "$wd/s.scene"
    trace_session "$BIN" "$wd" scene s.scene n
    rc=$?
    [ "$rc" -eq 2 ] && grep -q "$2" "$wd/err" || { echo "rc $rc"; cat "$wd/err"; return 1; }
    ! ls "$wd" | grep -q '\.part$'
}
SRC='source ray from 0 0 -5 dir 0 0 1'
DET='plane detect at 0 0 60 normal 0 0 1 disc 9'
check "wavelength: an unknown glass is refused with FILE:LINE" wl_bad glass \
    "s.scene:1: plane: 'refract': 'N-BK8' is neither a number nor a glass" \
    "plane refract 1 N-BK8 at 0 0 0 normal 0 0 1 disc 9
$DET
$SRC"
check "wavelength: a wavelength outside a glass's formula is refused" wl_bad range \
    "s.scene:1: N-BK7 has no index at 3000 nm: its formula holds from 300 to 2500 nm" \
    "plane refract 1 N-BK7 at 0 0 0 normal 0 0 1 disc 9
$DET
$SRC lambda 3000"
# A wavelength where a glass has an index but its transmittance table does not reach:
# traced, not refused, with the absorption of the table's nearest end (F2 at 325 nm:
# its index holds from 320 nm, its table is 0 at 320 and 0.211 at 334 nm), and a
# warning on the screen and in the record, once for the glass on both faces.
wl_held() {   # NAME GLASS THICKNESS NM UM T-AT-THE-END WARNING
    wl_trace "$1" "plane refract 1 $2 at 0 0 0 normal 0 0 1 disc 20
plane refract $2 1 at 0 0 $3 normal 0 0 1 disc 20
plane detect at 0 0 100 normal 0 0 1 disc 50
source ray from 0 0 -5 dir 0 0 1 lambda $4
reflections off
output summary s.sum" || return 1
    wd=$WW/$1
    [ "$(grep -c "^Warning: s.scene:1: $7" "$wd/out")" -eq 1 ] &&
        [ "$(grep -c "^Warning: s.scene:1: $7" "$wd/r.rec")" -eq 1 ] &&
        ! grep -q "s.scene:2: $2's internal" "$wd/out" || { cat "$wd/out"; return 1; }
    wn=$(sellmeier "$2" "$5") || return 1
    awk -v n="$wn" -v t="$6" -v L="$3" '$1 == "detected" { got = $2 }
        END { R = ((n - 1) / (n + 1)) ^ 2; want = (1 - R) ^ 2 * exp(log(t) / 25 * L)
              e = (got - want) / want; if (e < 0) e = -e
              printf "detected %.15g, (1-R)^2 T^(L/25) %.15g, error %.2g\n", got, want, e
              exit !(e < 1e-12) }' "$wd/s.sum"
}
check "wavelength: outside a glass's transmittance data (F2 at 325 nm) traced with its 334 nm absorption, and a warning" \
    wl_held heldF2 F2 25 325 0.325 0.211 \
    "F2's internal transmittance is known from 334 to 2500 nm, not at 325 nm: traced with its absorption at 334 nm"
check "wavelength: fused silica at 3 um (index to 3.71 um, SCHOTT's table to 2.325 um) is traced, with a warning" \
    wl_held heldsilica F_SILICA 10 3000 3.0 0.796739 \
    "F_SILICA's internal transmittance is known from 250 to 2325 nm, not at 3000 nm: traced with its absorption at 2325 nm"
check "wavelength: a bad wavelength is refused" wl_bad badwl \
    "s.scene:3: source ray: 'lambda': 'X' is not a wavelength" \
    "plane refract 1 N-BK7 at 0 0 0 normal 0 0 1 disc 9
$DET
$SRC lambda F X"
check "wavelength: a wavelength given twice is refused" wl_bad twice \
    "given twice" \
    "plane refract 1 N-BK7 at 0 0 0 normal 0 0 1 disc 9
$DET
$SRC lambda 587.5618 d"
check "wavelength: a source starting in silicon with no wavelength named is refused" wl_bad si \
    "SILICON has no index at 587.5618 nm" \
    "plane refract 1 1 at 0 0 0 normal 0 0 1 disc 9
$DET
$SRC medium silicon"

# The example scenes keep their bytes (outputs made before wavelengths existed).
wl_bytes() {
    sums=$TOP/golden/trace/scenes.sha256
    [ -f "$sums" ] || { echo "no $sums"; return 1; }
    for s in singlet prism opticrt periscope; do   # run where the scene is (its name
        wd=$WW/old_$s; rm -rf "$wd"; mkdir -p "$wd"     # goes into the summary)
        cp "$TOP"/scenes/* "$wd/"
        trace_session "$BIN" "$wd" scene "$s.scene" n || { cat "$wd/err"; return 1; }
    done
    (cd "$WW" && sha256sum -c --quiet "$sums")
}
check "wavelength: the example scenes' outputs are byte-identical to the tracer's before wavelengths" wl_bytes
