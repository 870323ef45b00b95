#!/bin/sh
# bench_wave.sh -- the wave engine (tests/wave/bench_wave.c): accuracy against closed
# forms (Airy, its encircled energy, the diffraction-limited MTF, Kirchhoff, Marechal,
# a quarter-wave coating, the TIR phases), a 512 x 512 PSF and its MTF on one core
# against two bare FFTs, and the pupil grid against error and run time.
B=build/obj/wave_tests/bench_wave
[ -x "$B" ] || { echo "bench_wave: $B not built (make bench builds it)" >&2; exit 1; }
echo "# machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg); one thread"
"$B" || exit 1
# No MTF, Strehl or encircled-energy figure printed with its full prescription was
# found for a public lens (doc/wave.md says what was searched); instead the triplet's
# MTF (d line, fields 0 and 14 degrees, 128-cell grid) against an independent
# implementation (tests/wave/mtf_quad.py: the pupil's autocorrelation by quadrature).
W=$(mktemp -d) || exit 1
trap 'rm -rf "$W"' EXIT
sed 's/^wavelengths d F C/wavelengths d/' doc/pupil-triplet.rx > "$W/t1.rx"
printf '%s\n128\nfringe\n37\n100\n0\n-\n' "$W/t1.rx" | ./lensmat --wave "$W/t1.rec" > /dev/null 2>&1 &&
/usr/bin/python3 tests/wave/mtf_quad.py "$W/t1.rec" |
    awk '$1 <= 2 { for (i = 0; i < 2; i++) { d = $(3 + i) - $(5 + i); if (d < 0) d = -d; if (d > m) m = d } }
         END { printf "BENCH wave_triplet_mtf_vs_quadrature_abs_err %.3g ratio\n", m }'
# Polarization ray tracing (issue 21; src/trace/tr_polar.c): the traced interface's PRT
# amplitudes against Hecht's forms, a traced Fresnel rhomb's retardance against the TIR
# closed form and Born & Wolf's 2 x 45 degrees, Malus, a traced coating against the
# quarter-wave closed form (tests/trace/t_polar.c, whose checks these are); what
# polarization costs on the triplet against the unpolarized paths of the same run
# (tests/trace/bench_polar.c), and the unpolarized ray-by-ray loop it mirrors.
T=build/obj/trace_tests/t_polar P=build/obj/trace_tests/bench_polar
if [ -x "$T" ] && [ -x "$P" ]; then
    "$T" | grep '^BENCH'
    "$P"
    LENSMAT_ISA=scalar "$P" unpolarized
else echo "bench_wave: $T or $P not built (make bench builds them)" >&2; exit 1; fi
