# t_94_wave.sh -- the wave-optics engine (src/wave/): closed forms (t_closed: Airy,
# its encircled energy, the diffraction-limited MTF, FFT against Kirchhoff, Strehl
# against Marechal, Rayleigh and Sparrow, Zernike orderings and fit), the calculators
# (t_calc: thin films, Fresnel and TIR phases, Jones, Gaussian beams), the trace
# module's rx_opd against a Cartesian ellipsoid (t_opd), the triplet's
# MTF against an independent quadrature (mtf_quad.py); normal and sanitizer builds; the
# module's exports; lensmat itself not linking FFTW; the --wave dialogue.
for b in t_closed t_calc t_opd; do
    unit "$TOP/build/obj/wave_tests/$b"
    unit "$TOP/build/asan/wave_tests/$b"
done
check "lensmat-wave.so exports wave_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-wave.so' | grep ' T ' | awk '{print \$3}')\" = wave_get_api"
check "lensmat-wave.so links FFTW" sh -c "ldd '$TOP/build/lib/lensmat-wave.so' | grep -q libfftw3"
check "./lensmat does not link FFTW (the wave engine is loaded on first use)" sh -c \
    "! ldd '$BIN' | grep -q fftw"
# --wave: the example (the Zemax tutorial's Cooke triplet, doc/pupil-triplet.rx) runs,
# states its sampling and orderings, and replays exactly from its grep'd record
wave_dir() { mkdir -p "$WORK/wv" && ln -sfn "$TOP/doc" "$WORK/wv/doc"; }
wave_example() (
    wave_dir && cd "$WORK/wv" && "$1" --wave --example w.rec > w.out 2> w.err || return 1
    grep -q '^Pupil: 64 x 64 cells across the stop .* FFT 256 x 256 (Q 4' w.rec || return 1
    grep -q '^Zernike ordering: Fringe, 37 terms' w.rec || return 1
    grep -q '^  Zernike fit at 587.562 nm (Fringe): residual RMS' w.rec || return 1
    grep -q 'MTF (cutoff' w.rec && grep -q 'Strehl ratio' w.rec && grep -q 'encircled energy' w.rec || return 1
    [ "$(grep -c '^Field ' w.rec)" = 3 ] || return 1
    grep input: w.rec | sed 's/^input: //' > w.in && "$1" --wave w2.rec < w.in > /dev/null 2>&1 &&
        cmp w.rec w2.rec
)
check "--wave: example (triplet): sampling, Zernike, Strehl, EE, MTF per field; replays exactly" \
    wave_example "$BIN"
check "--wave: the same under ASan/UBSan" wave_example "$ASAN"
# The wavefront through rx_opd (tr_opd.c) against --pupil's own (pupil.c) on the same
# 32-cell grid: every field's and wavelength's RMS and PV agree to the digits printed
wave_vs_pupil() (
    wave_dir && cd "$WORK/wv" &&
    printf 'doc/pupil-triplet.rx\ngrid\n32\nn\n' | "$BIN" --pupil p32.rec > p.out 2>&1 &&
    printf 'doc/pupil-triplet.rx\n32\nnoll\n11\n0\n0\n-\n' | "$BIN" --wave w32.rec > w32.out 2>&1 &&
    grep 'RMS .* waves, peak to valley' p.out | awk '{printf "%.4f %.3g\n", $2, $7}' | sort > a &&
    grep 'nm: W RMS' w32.out | awk '{printf "%.4f %.3g\n", $5, $7}' | sort > b &&
    [ -s a ] && [ "$(wc -l < a)" = 9 ] && cmp a b
)
check "--wave: W RMS and PV = --pupil's for 3 fields x 3 wavelengths (independent paths)" wave_vs_pupil
# A slow singlet (f/40 on the axis, at its paraxial focus): diffraction-limited, so
# the MTF lies on the diffraction limit, the cutoff is 1/(lambda N) with N --pupil's
# working f-number, and 83.8 % of the energy is within the Airy radius (1 - J0^2 - J1^2
# at the first zero of J1: 0.8378)
wave_slow() (
    wave_dir && cd "$WORK/wv" &&
    printf '%s\n' thickness 'title slow' 'wavelengths d' 'epd 2.5' 'field angle 0' 'index air' \
        '51.68 3 N-BK7 stop' 'inf 0 air' > slow.rx &&
    printf 'slow.rx\n64\nansi\n15\n0\n0\n-\n' | "$BIN" --wave s.rec > s.out 2>&1 &&
    printf 'slow.rx\ngrid\n4\nn\n' | "$BIN" --pupil sp.rec > sp.out 2>&1 &&
    N=$(grep 'working f-number' sp.out | head -1 | sed 's/.*working f-number \([0-9.]*\),.*/\1/') &&
    cut=$(grep 'MTF (cutoff' s.out | sed 's/.*cutoff \([0-9.]*\) .*/\1/') &&
    awk -v n="$N" -v c="$cut" 'BEGIN { w = 1 / (0.000587562 * n); exit !(c / w > 0.995 && c / w < 1.005) }' &&
    grep 'Strehl ratio' s.out | awk '{ exit !($3 > 0.999) }' &&
    grep -q 'encircled energy: 83.8% within the Airy radius' s.out &&
    awk '/cycles\/mm  tangential/ { t = 1; next } t && NF == 4 { d = $2 - $4; if (d < 0) d = -d;
         if (d > m) m = d; n++; next } t { t = 0 } END { exit !(n == 11 && m < 3e-3) }' s.out
)
check "--wave: a diffraction-limited f/40 singlet: Strehl > 0.999, EE(Airy) 83.8%, MTF on the limit, cutoff 1/(lambda N)" wave_slow
# Bad answers: a 8-cell grid and a 38-term fit are refused in a replay with FILE:LINE
wave_bad() (
    wave_dir && cd "$WORK/wv" && printf 'doc/pupil-triplet.rx\n8\n' > bad.in &&
    "$BIN" --wave -i bad.in bad.rec > /dev/null 2> bad.err; rc=$?
    [ "$rc" = 2 ] && grep -q 'bad.in:2' bad.err || return 1
    printf 'doc/pupil-triplet.rx\n32\nfringe\n38\n' > bad2.in &&
    "$BIN" --wave -i bad2.in bad2.rec > /dev/null 2> bad2.err; rc=$?
    [ "$rc" = 2 ] && grep -q 'bad2.in:4' bad2.err
)
check "--wave: an 8-cell grid and 38 Zernike terms refused (FILE:LINE, exit 2)" wave_bad
# The triplet's MTF (one wavelength, fields 1 and 2: unvignetted) against an
# independent implementation (tests/wave/mtf_quad.py: the pupil's autocorrelation by
# Gauss-Legendre quadrature over the circles' overlap, W from the record's Zernike
# table; no FFT, no grid): within 2.5e-3 at every tabulated frequency
wave_quad() (
    wave_dir && cd "$WORK/wv" && sed 's/^wavelengths d F C/wavelengths d/' doc/pupil-triplet.rx > t1.rx &&
    printf 't1.rx\n128\nfringe\n37\n100\n0\n-\n' | "$BIN" --wave t1.rec > /dev/null 2>&1 &&
    /usr/bin/python3 "$TOP/tests/wave/mtf_quad.py" t1.rec > q.out &&
    awk '$1 <= 2 { for (i = 0; i < 2; i++) { d = $(3 + i) - $(5 + i); if (d < 0) d = -d; if (d > m) m = d }; n++ }
         END { print "largest difference", m, "over", n, "rows"; exit !(n == 22 && m < 2.5e-3) }' q.out
)
check "--wave: triplet MTF = pupil autocorrelation by quadrature (independent) within 2.5e-3" wave_quad
# Pictures through the imaging module: per field the wavefront and PSF maps (PNG) and
# the MTF, through-focus and Zernike plots (PNG and SVG); a name with an extension is
# refused
wave_pics() (
    wave_dir && cd "$WORK/wv" &&
    printf 'doc/pupil-triplet.rx\n32\nnoll\n11\n0\n0.02\n1\n40\npic/tw\n' > pic.in && mkdir -p pic &&
    "$BIN" --wave -i pic.in pic.rec > pic.out 2>&1 || return 1
    for f in 1 2 3; do
        for p in wavefront psf psf-log mtf focus zernike; do
            head -c 8 "pic/tw-f$f-$p.png" | od -An -c | grep -q 'P   N   G' || { echo "pic/tw-f$f-$p.png"; return 1; }
        done
        for p in mtf focus zernike; do grep -q '<svg' "pic/tw-f$f-$p.svg" || return 1; done
    done
    [ "$(grep -c '^Pictures: ' pic.rec)" = 3 ] || return 1
    printf 'doc/pupil-triplet.rx\n32\nnoll\n11\n0\n0\nx.png\n' > pb.in
    "$BIN" --wave -i pb.in pb.rec > /dev/null 2> pb.err; [ $? = 2 ] && grep -q 'pb.in:7' pb.err
)
if [ -f "$TOP/build/lib/lensmat-imaging.so" ]; then
    check "--wave: pictures (wavefront, PSF linear and log, MTF, through focus, Zernike; PNG, SVG)" wave_pics
else fail "--wave pictures: build/lib/lensmat-imaging.so not built"; fi
# --beam and --polar: their examples replay exactly; --beam against the closed forms
# (a waist w0 at the front focal plane of a lens f images to a waist lambda f/(pi w0)
# at the back focal plane; zR = pi w0^2/lambda), --polar against the seed's circular
# polarization (45-degree light through a quarter-wave plate: Stokes 1 0 0 1), the
# TIR phase formula, and a quarter-wave MgF2 layer's closed form
calc_replay() (
    wave_dir && cd "$WORK/wv" && "$BIN" --$1 --example $1.rec > $1.out 2>&1 &&
    grep input: $1.rec | sed 's/^input: //' > $1.in && "$BIN" --$1 $1-2.rec < $1.in > /dev/null 2>&1 &&
    cmp $1.rec $1-2.rec
)
check "--beam: example replays exactly" calc_replay beam
check "--polar: example replays exactly" calc_replay polar
wave_beam() (
    wave_dir && cd "$WORK/wv" &&
    printf 'mm\n632.8\n1\n1\n0.5\n0\nlens\n100\n100\nend\n500\n' | "$BIN" --beam bm.rec > bm.out 2>&1 &&
    grep 'After it' bm.out | sed 's/.*waist w0= \([^ ]*\) at z= \([^,]*\),.*/\1 \2/' |
        awk '{ want = 632.8e-6 * 100 / (3.14159265358979 * 0.5); r = $1 / want - 1
               exit !(NF == 2 && r < 1e-5 && r > -1e-5 && ($2 - 200) ^ 2 < 1e-12) }' &&
    grep 'Small on both planes' bm.out | sed 's/.*= \([0-9.]*\) midway.*sqrt(2) w0 = \([0-9.]*\) on both.*/\1 \2/' |
        awk '{ w = sqrt(632.8e-6 * 500 / (2 * 3.14159265358979)); r = $1 / w - 1; q = $2 / ($1 * sqrt(2)) - 1
               exit !(NF == 2 && r < 1e-5 && r > -1e-5 && q < 1e-5 && q > -1e-5) }'
)
check "--beam: a waist at the front focus images to lambda f/(pi w0) at the back focus; the two-plane balance" wave_beam
asan_replay() (
    wave_dir && cd "$WORK/wv" && "$ASAN" --$1 --example a$1.rec > /dev/null 2>&1 &&
    grep input: a$1.rec | sed 's/^input: //' | "$ASAN" --$1 a$1-2.rec > /dev/null 2>&1 && cmp a$1.rec a$1-2.rec
)
check "--beam: example replays exactly under ASan/UBSan" asan_replay beam
check "--polar: example replays exactly under ASan/UBSan" asan_replay polar
wave_polar() (
    wave_dir && cd "$WORK/wv" &&
    printf 'jones\nd\n1\nqwp\n0\n' | "$BIN" --polar pj.rec > pj.out 2>&1 &&
    grep -q '1 qwp 0: .*Stokes 1 0 0 1 $' pj.out &&
    printf 'fresnel\n1.5\n1\n60\n' | "$BIN" --polar pf.rec > pf.out 2>&1 &&
    grep 'total internal' pf.out | sed 's/.*is \(-*[0-9.]*\) deg.*: \(-*[0-9.]*\) deg.*/\1 \2/' |
        awk '{ exit !($1 == $2 && $1 != "") }' &&
    printf 'film\n1\n1.5168\n550\n1\n1.38\n0\n0\n' | "$BIN" --polar pm.rec > pm.out 2>&1 &&
    grep -q '^   550.0 nm: Rs 1.28354%' pm.out && grep -q '= 1.28354%' pm.out
)
check "--polar: circular light from a quarter-wave plate, the TIR phase, a quarter-wave MgF2 coating" wave_polar
# SIGINT during a 512-cell run (seconds of aimed rays): the chunked rx_opd calls poll
# the stop flag, lensmat exits 130, no field report and no picture left behind
wave_stop() {
    wave_dir
    printf 'doc/pupil-triplet.rx\n512\nfringe\n37\n0\n0\nstop/tw\n' > "$WORK/wv/ws.in"
    mkdir -p "$WORK/wv/stop"
    (cd "$WORK/wv" && exec "$TOP/lensmat" --wave ws.rec < ws.in > ws.out 2> ws.err) &
    p=$!
    sleep 0.5
    kill -INT "$p"
    wait "$p"
    rc=$?
    [ "$rc" -eq 130 ] || { echo "exit $rc"; cat "$WORK/wv/ws.err"; return 1; }
    ! grep -q "Strehl ratio" "$WORK/wv/ws.out" && [ -z "$(ls "$WORK/wv/stop")" ] &&
        grep -q "stopped by signal 2" "$WORK/wv/ws.err" && grep -q "^Stopped by signal 2" "$WORK/wv/ws.out"
}
check "--wave stops on SIGINT mid-trace (exit 130, no report, no picture)" wave_stop
# Through focus against refocusing: the triplet at d on the axis, the MTF at 50
# cycles/mm and the Strehl ratio 0.07 mm beyond the image plane by the W020 model,
# against a run with the image plane moved there (traced again): within 0.01
wave_focus() (
    wave_dir && cd "$WORK/wv" && sed 's/^wavelengths d F C/wavelengths d/' doc/pupil-triplet.rx > f1.rx &&
    sed 's/^-18.39533   42.20778/-18.39533   42.27778/' f1.rx > f2.rx && ! cmp -s f1.rx f2.rx &&
    printf 'f1.rx\n64\nnoll\n11\n100\n0.07\n1\n50\n-\n' | "$BIN" --wave f1.rec > f1.out 2>&1 &&
    printf 'f2.rx\n64\nnoll\n11\n100\n0\n-\n' | "$BIN" --wave f2.rec > f2.out 2>&1 &&
    a=$(awk '/through focus/ { t = 1 } t && $1 == "0.07" { print $2, $4; exit }' f1.out) &&
    b=$(awk '/^Field 2/ { exit } /587.6 nm: W/ { s = $15 + 0 } /diffraction/ { t = 1 } t && $1 == "50" { print $2, s; exit }' f2.out) &&
    echo "model: $a; refocused: $b" &&
    echo "$a $b" | awk '{ d1 = $1 - $3; d2 = $2 - $4; if (d1 < 0) d1 = -d1; if (d2 < 0) d2 = -d2;
                          exit !(NF == 4 && d1 < 0.01 && d2 < 0.01) }'
)
check "--wave: through focus (W020 model) = the image plane moved and traced again, within 0.01" wave_focus
# Fields off the meridional plane: the tangential cut turns toward the field's image
# point (otf_dir), so 14 degrees in x gives the 14-degree y field's MTF exactly (the
# grid is symmetric about the diagonal); 10 degrees in x and y (14.0 off the axis,
# one wavelength, a 256-cell grid: at 64 cells the square grid's rim, turned 45
# degrees against the astigmatism, costs 0.02) the same within 3e-3
wave_mtf_rows() {   # FILE: "field freq T S" for every MTF row
    awk '/^Field/ { f++; t = 0; next } /cycles\/mm  tangential/ { t = 1; next }
         t && NF == 4 { print f, $1, $2, $3; next } { t = 0 }' "$1"
}
wave_xy() (
    wave_dir && cd "$WORK/wv" &&
    sed 's/^field angle 0 14 20/field angle 14,0 0,14/' doc/pupil-triplet.rx > xy.rx &&
    printf 'xy.rx\n64\nnoll\n11\n100\n0\n-\n' | "$BIN" --wave xy.rec > xy.out 2>&1 &&
    grep -q '^Field 1: 14 degrees in x, 0 in y' xy.out &&
    wave_mtf_rows xy.out > xy.rows && [ "$(wc -l < xy.rows)" = 22 ] &&
    awk '$1 == 1 { a[$2] = ($3 " " $4) } $1 == 2 && a[$2] != ($3 " " $4) { exit 1 }' xy.rows &&
    sed 's/^field angle 0 14 20/field angle 0,14 10,10/; s/^wavelengths d F C/wavelengths d/' \
        doc/pupil-triplet.rx > xd.rx &&
    printf 'xd.rx\n256\nnoll\n11\n100\n0\n-\n' | "$BIN" --wave xd.rec > xd.out 2>&1 &&
    wave_mtf_rows xd.out | awk '$1 == 1 { t[$2] = $3; s[$2] = $4; next }
        { d = $3 - t[$2]; e = $4 - s[$2]; if (d < 0) d = -d; if (e < 0) e = -e; if (d > m) m = d; if (e > m) m = e; n++ }
        END { print "diagonal against y: largest difference", m; exit !(n == 11 && m < 3e-3) }'
)
check "--wave: an x field's tangential and sagittal MTF = the y field's; the diagonal within 3e-3" wave_xy
