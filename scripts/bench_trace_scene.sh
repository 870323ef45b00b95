#!/bin/sh
# bench_trace_scene.sh -- the Cooke triplet traced the way users trace it: a scene
# file through `lensmat --trace` (tests/trace/tt.h's prescription with mounts and a
# detector at the paraxial image, 1128 x 1128 collimated grid = 999 332 rays, Fresnel
# on, reflections off, one thread), next to the same workload through the engine's
# API (`bench_trace triplet`, add_lens) in the same run, interleaved, medians of 3:
#   trace_scene_triplet_mrays_per_s       the rays/s lensmat reports (trace only)
#   trace_scene_triplet_api_mrays_per_s   the API figure of the same run
#   trace_scene_triplet_vs_api            their ratio (target >= 0.9)
#   trace_scene_triplet_wall_mrays_per_s  rays / the whole lensmat process (start,
#                                         module load, scene, build, trace)
#   trace_scene_triplet_vs_bvh            against LENSMAT_TRACE_BVH=1 (every segment
#                                         by Embree, the speed before tr_seqscan.c)
#   trace_scene_triplet_hits_mrays_per_s  the same with `output hits` (a 999 332-row
#                                         CSV written: what the text output costs)
# The scene asks for its summary only, the API run keeps a hit sink (the spot).
set -e
LM=$(pwd)/lensmat
B=$(pwd)/build/obj/trace_tests/bench_trace
[ -x "$LM" ] && [ -x "$B" ] || { echo "bench_trace_scene: lensmat or $B not built" >&2; exit 1; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
isa=$(grep -m1 -o -w 'avx512f' /proc/cpuinfo || grep -m1 -o -w 'avx2' /proc/cpuinfo || uname -m)
echo "# bench_trace_scene on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, $isa (LENSMAT_ISA=${LENSMAT_ISA:-auto}), load $(cut -d' ' -f1-3 /proc/loadavg); one thread"
GRID=${BENCH_QUICK:+400}
awk -v grid="${GRID:-1128}" 'BEGIN {
    split("22.01359 -435.76044 -22.21328 20.29192 79.68360 -18.39533", R, " ")
    split("3.25896 6.00764 0.99963 4.75041 2.95208 42.20778", T, " ")
    split("1.62041 1.0 1.62004 1.0 1.62041 1.0", N, " ")
    split("8.0 8.0 5.5 5.5 7.5 7.5", SD, " ")
    n = 1; z = 0
    print "# Cooke triplet f/4 (tests/trace/tt.h), mounts, detector at the paraxial image"
    for (i = 1; i <= 6; i++) {
        c = 1 / R[i]; s = SD[i]; sag = c * s * s / (1 + sqrt(1 - c * c * s * s))
        printf "cap refract %s %s vertex 0 0 %.17g radius %s aperture %s\n", n, N[i], z, R[i], SD[i]
        printf "plane absorb at 0 0 %.17g normal 0 0 1 disc 40 hole %s\n", z + sag, SD[i]
        n = N[i]; z += T[i]
    }
    print "plane detect at 0 0 60.404971618172183 normal 0 0 1 disc 50"
    printf "source collimated from 0 0 -5 dir 0 0 1 radius 6.25 grid %d\n", grid
    print "reflections off\nthreads 1\noutput summary triplet.sum" }' > "$W/triplet.scene"
cp "$W/triplet.scene" "$W/hits.scene"
echo "output hits triplet-hits.csv" >> "$W/hits.scene"
printf 'scene\n%s\nn\n' "$W/triplet.scene" > "$W/in"
printf 'scene\n%s\nn\n' "$W/hits.scene" > "$W/in_hits"

# one lensmat run: "rays/s wall_rays/s" (rays/s as lensmat prints it)
scene_run() {
    t0=$(date +%s%N)
    (cd "$W" && "$LM" --trace -i "$1" r.rec > out)
    t1=$(date +%s%N)
    awk -v ns=$((t1 - t0)) '/^Rays traced:/ { r = $3 + 0 }
        /^Build .* rays\/s/ { s = $0; sub(/.*\(/, "", s); sub(/ rays.*/, "", s) }
        END { if (!r || !s) exit 1; printf "%.6g %.6g\n", s, r / (ns / 1e9) }' "$W/out"
}
api_run() { "$B" triplet | awk '$2 == "trace_triplet_mrays_per_s" { print $3 * 1e6 }'; }

: > "$W/s"; : > "$W/a"
for i in 1 2 3; do
    scene_run in >> "$W/s"
    api_run >> "$W/a"
done
bvh=$(LENSMAT_TRACE_BVH=1 scene_run in | cut -d' ' -f1)
hits=$(scene_run in_hits | cut -d' ' -f1)
med() { sort -g | sed -n 2p; }
s=$(cut -d' ' -f1 "$W/s" | med); w=$(cut -d' ' -f2 "$W/s" | med); a=$(med < "$W/a")
awk -v s="$s" -v w="$w" -v a="$a" -v b="$bvh" -v h="$hits" 'BEGIN {
    printf "BENCH trace_scene_triplet_mrays_per_s %.3f Mrays/s\n", s / 1e6
    printf "BENCH trace_scene_triplet_api_mrays_per_s %.3f Mrays/s\n", a / 1e6
    printf "BENCH trace_scene_triplet_vs_api %.2f ratio\n", s / a
    printf "BENCH trace_scene_triplet_wall_mrays_per_s %.3f Mrays/s\n", w / 1e6
    printf "BENCH trace_scene_triplet_vs_bvh %.2f ratio\n", s / b
    printf "BENCH trace_scene_triplet_hits_mrays_per_s %.3f Mrays/s\n", h / 1e6 }'
