#!/bin/sh
# bench_imaging.sh -- the imaging engine's frame and centroid figures (issue 10):
# centroid accuracy against the Cramer-Rao bound on 1000 synthetic 640x480 16-bit frames
# and the time per frame of each method (tests/imaging/bench_centroid.c; the method
# table goes to build/bench/centroid_methods.tsv and is plotted, error against time on
# log-log axes, to build/bench/centroid_methods.png and .svg), the synthesis time, and
# the cost of loading the module for the first frame and the camera module for the first
# video frame (tests/imaging/bench_load.c, median of 7 fresh processes), and issue 19's
# front end (saturation, detection, camera gain: tests/imaging/t_front.c).
# BENCH_QUICK=1: 200 frames, 3 processes.
B=build/obj/imaging_tests
for b in bench_centroid bench_load t_front; do
    [ -x "$B/$b" ] || { echo "bench_imaging: $B/$b not built (make bench builds it)" >&2; exit 1; }
done
n=1000; runs=7
[ -n "$BENCH_QUICK" ] && { n=200; runs=3; }
echo "# machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; one thread"
mkdir -p build/bench
# (its PLOT box/marker lines, the pixels of the markers, are for the tests)
out=$("$B/bench_centroid" "$n" build/bench/centroid_methods.tsv build/bench/centroid_methods.png) || exit 1
printf '%s\n' "$out" | grep -v '^PLOT [bm]'

tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
"$B/bench_load" build/lib --make-avi "$tmp/v.avi" || exit 1
i=0
while [ $i -lt $runs ]; do
    "$B/bench_load" build/lib tests/imaging/fuzz-corpus/g16.png "$tmp/v.avi" >> "$tmp/load" || exit 1
    i=$((i + 1))
done
med() { sort -n | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }
echo "BENCH imaging_load_ms $(cut -d' ' -f1 "$tmp/load" | med) ms"
echo "BENCH imaging_first_read_ms $(cut -d' ' -f2 "$tmp/load" | med) ms"
echo "BENCH camera_load_ms $(cut -d' ' -f3 "$tmp/load" | med) ms"
# issue 19's front end (tests/imaging/t_front.c, frames from its own forward model): the
# share of saturated 12-bit spots in 16-bit frames flagged, the share of A = 5 sigma
# spots found at threshold 5, the camera gain from photon transfer over the true one
"$B/t_front" | grep '^BENCH imaging_' || exit 1
