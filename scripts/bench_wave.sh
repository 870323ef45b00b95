#!/bin/sh
# bench_wave.sh -- the wave engine (tests/wave/bench_wave.c): accuracy against closed
# forms (Airy, its encircled energy, the diffraction-limited MTF, Kirchhoff, Marechal,
# a quarter-wave coating, the TIR phases), a 512 x 512 PSF and its MTF on one core
# against two bare FFTs, and the pupil grid against error and run time.
B=build/obj/wave_tests/bench_wave
[ -x "$B" ] || { echo "bench_wave: $B not built (make bench builds it)" >&2; exit 1; }
echo "# machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg); one thread"
exec "$B"
