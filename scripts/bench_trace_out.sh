#!/bin/sh
# bench_trace_out.sh -- what writing every detector hit costs (issue 23): the Cooke
# triplet scene of bench_trace_scene.sh (1128 x 1128 collimated grid = 999 332 rays,
# Fresnel on, reflections off, one thread; nearly every ray reaches the detector)
# traced by `lensmat --trace` with no hit output, with `output hits F.csv` (shortest
# round-trip numbers), F.npy, F.h5 and F.csv csv17 (the "%.17g" CSV of before), runs
# interleaved, medians of 3 (csv17 once: it is the slow one).  The time is the trace
# time lensmat reports (the hits are written inside the trace, from its sink), so
#   trace_hits_csv_cost    trace time with every hit written as CSV / without (<= 2)
#   trace_hits_npy_cost    the same for .npy (<= 1.2)
#   trace_hits_h5_cost     the same for HDF5 (tables assembled in memory, written once)
#   trace_hits_csv17_cost  the CSV of before, for comparison
#   trace_hits_csv_mrays_per_s  rays/s with every hit written as CSV
#   trace_hits_{csv,npy}_cpu_cost  the same ratios in CPU time of the whole lensmat
#                          process (every thread: the writer's too; start and scene
#                          read included, the same in both): what the output costs
#                          in work, whatever else the machine is doing
# BENCH_QUICK=1: a 400 x 400 grid.
set -e
LM=$(pwd)/lensmat
[ -x "$LM" ] && [ -f build/lib/lensmat-trace.so ] || { echo "bench_trace_out: lensmat or its trace module not built" >&2; exit 1; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
isa=$(grep -m1 -o -w 'avx512f' /proc/cpuinfo || grep -m1 -o -w 'avx2' /proc/cpuinfo || uname -m)
echo "# bench_trace_out on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, $isa, load $(cut -d' ' -f1-3 /proc/loadavg); one thread; outputs to $(df -PT "$W" | awk 'NR == 2 { print $2 }')"
GRID=${BENCH_QUICK:+400}
awk -v grid="${GRID:-1128}" 'BEGIN {
    split("22.01359 -435.76044 -22.21328 20.29192 79.68360 -18.39533", R, " ")
    split("3.25896 6.00764 0.99963 4.75041 2.95208 42.20778", T, " ")
    split("1.62041 1.0 1.62004 1.0 1.62041 1.0", N, " ")
    split("8.0 8.0 5.5 5.5 7.5 7.5", SD, " ")
    n = 1; z = 0
    for (i = 1; i <= 6; i++) {
        c = 1 / R[i]; s = SD[i]; sag = c * s * s / (1 + sqrt(1 - c * c * s * s))
        printf "cap refract %s %s vertex 0 0 %.17g radius %s aperture %s\n", n, N[i], z, R[i], SD[i]
        printf "plane absorb at 0 0 %.17g normal 0 0 1 disc 40 hole %s\n", z + sag, SD[i]
        n = N[i]; z += T[i]
    }
    print "plane detect at 0 0 60.404971618172183 normal 0 0 1 disc 50"
    printf "source collimated from 0 0 -5 dir 0 0 1 radius 6.25 grid %d\n", grid
    print "reflections off\nthreads 1" }' > "$W/base"
for k in none csv npy h5 csv17; do
    cp "$W/base" "$W/$k.scene"
    case $k in
    none) ;;
    csv17) echo "output hits hits17.csv csv17" >> "$W/$k.scene" ;;
    *) echo "output hits hits.$k" >> "$W/$k.scene" ;;
    esac
    printf 'scene\n%s\nn\n' "$W/$k.scene" > "$W/in_$k"
done

# one lensmat run: the trace time in ms, the rays and hits, the process's CPU seconds
run() {
    (cd "$W" && /usr/bin/time -f '%U %S' -o cpu "$LM" --trace -i "in_$1" r.rec > out &&
     rm -f hits.* hits17.csv)
    awk -v cpu="$(awk '{ print $1 + $2 }' "$W/cpu")" '/^Rays traced:/ { r = $3 + 0 } /^Detector hits:/ { h = $3 + 0 }
        /^Build .* rays\/s/ { s = $0; sub(/.*\(/, "", s); sub(/ rays.*/, "", s) }
        END { if (!r || !s) exit 1; printf "%.6g %d %d %s\n", r / s * 1e3, r, h, cpu }' "$W/out"
}
for i in 1 2 3; do
    for k in none csv npy h5; do run $k >> "$W/t_$k"; done
done
run csv17 >> "$W/t_csv17"
med() { cut -d' ' -f"${2:-1}" "$W/t_$1" | sort -g | sed -n "$(( ($(wc -l < "$W/t_$1") + 1) / 2 ))p"; }
read -r _ rays hits _ < "$W/t_none"
echo "# $rays rays, $hits hits; trace ms (medians): none $(med none), csv $(med csv), npy $(med npy), h5 $(med h5), csv17 $(med csv17); process CPU s: none $(med none 4), csv $(med csv 4), npy $(med npy 4), csv17 $(med csv17 4)"
awk -v n="$(med none)" -v c="$(med csv)" -v p="$(med npy)" -v h="$(med h5)" -v o="$(med csv17)" -v r="$rays" 'BEGIN {
    printf "BENCH trace_hits_csv_cost %.2f ratio\n", c / n
    printf "BENCH trace_hits_npy_cost %.2f ratio\n", p / n
    printf "BENCH trace_hits_h5_cost %.2f ratio\n", h / n
    printf "BENCH trace_hits_csv17_cost %.2f ratio\n", o / n
    printf "BENCH trace_hits_csv_mrays_per_s %.3f Mrays/s\n", r / c / 1e3 }'
awk -v n="$(med none 4)" -v c="$(med csv 4)" -v p="$(med npy 4)" 'BEGIN {
    printf "BENCH trace_hits_csv_cpu_cost %.2f ratio\n", c / n
    printf "BENCH trace_hits_npy_cpu_cost %.2f ratio\n", p / n }'
