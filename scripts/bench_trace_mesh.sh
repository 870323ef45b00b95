#!/bin/sh
# bench_trace_mesh.sh -- what a mesh costs in memory (issue 23): a UV sphere of 998 000
# triangles (radius 10, 499 002 shared vertices) written as an OBJ (52 MB), traced by
# `lensmat --trace` as a refracting mesh (100 rays, one thread), against the same
# scene without the mesh; the peak resident memory of each lensmat process (getrusage
# of the child: VmHWM) in the same run:
#   trace_mesh_bytes_per_tri   (peak with the mesh - peak without) / triangles (<= 120)
#   trace_mesh_bytes_per_tri_one_bvh   the same with the mesh as one BVH
#                              (LENSMAT_TRACE_CHUNK=0: the layout before chunks)
#   trace_mesh_chunked_vs_one_bvh   what the chunks cost in speed: the same mesh traced
#                              by 125 676 rays (1.06 M segments), trace time as one BVH
#                              over the time in chunks, three alternated rounds, medians
# Then tests/trace/bench_mesh.c: trace_mesh_vs_raw_embree (see there).
# BENCH_QUICK=1: 248 000 triangles, smaller grids.
set -e
LM=$(pwd)/lensmat
[ -x "$LM" ] && [ -f build/lib/lensmat-trace.so ] || { echo "bench_trace_mesh: lensmat or its trace module not built" >&2; exit 1; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
echo "# bench_trace_mesh on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), MemAvailable $(awk '/MemAvailable/ { printf "%.0f MB", $2 / 1024 }' /proc/meminfo)"
NU=${BENCH_QUICK:+250}; NV=${BENCH_QUICK:+500}
python3 - "${NU:-500}" "${NV:-1000}" "$W/ball.obj" <<'PY'
import math, sys
nu, nv = int(sys.argv[1]), int(sys.argv[2])
with open(sys.argv[3], "w") as out:
    w = out.write
    w("v 0 0 10\n")
    for i in range(1, nu):
        th = math.pi * i / nu; z = 10 * math.cos(th); r = 10 * math.sin(th)
        w("".join("v %.17g %.17g %.17g\n" % (r * math.cos(2 * math.pi * j / nv),
              r * math.sin(2 * math.pi * j / nv), z) for j in range(nv)))
    w("v 0 0 -10\n")
    last = 2 + (nu - 1) * nv
    V = lambda i, j: 2 + (i - 1) * nv + (j % nv)
    w("".join("f 1 %d %d\n" % (V(1, j + 1), V(1, j)) for j in range(nv)))
    for i in range(1, nu - 1):
        w("".join("f %d %d %d\nf %d %d %d\n" % (V(i, j), V(i, j + 1), V(i + 1, j + 1),
              V(i, j), V(i + 1, j + 1), V(i + 1, j)) for j in range(nv)))
    w("".join("f %d %d %d\n" % (last, V(nu - 1, j), V(nu - 1, j + 1)) for j in range(nv)))
PY
printf '%s\n' "plane detect at 0 0 30 normal 0 0 1 disc 100" \
    "source collimated from 0 0 -20 dir 0 0 1 radius 5 grid 10" "threads 1" > "$W/empty.scene"
{ echo "mesh refract 1 1.5 file ball.obj"; cat "$W/empty.scene"; } > "$W/mesh.scene"
# peak KB of one lensmat run on SCENE (a child of its own python, so getrusage sees it alone)
peak() {
    LENSMAT_TRACE_CHUNK=$2 python3 - "$LM" "$W" "$1" <<'PY'
import resource, subprocess, sys
lm, w, scene = sys.argv[1:4]
p = subprocess.run([lm, "--trace", "-i", "/dev/stdin", w + "/r.rec"], cwd=w,
                   input=("scene\n%s\nn\n" % scene).encode(), capture_output=True)
if p.returncode: sys.exit("lensmat failed: " + p.stderr.decode()[-300:])
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
PY
}
nt=$(grep -c '^f' "$W/ball.obj")
e1=$(peak empty.scene); m1=$(peak mesh.scene); e2=$(peak empty.scene); m2=$(peak mesh.scene)
echo "# $nt triangles ($(($(wc -c < "$W/ball.obj") / 1048576)) MB OBJ): peak RSS $m1, $m2 KB with the mesh, $e1, $e2 KB without"
awk -v e1="$e1" -v e2="$e2" -v m1="$m1" -v m2="$m2" -v n="$nt" 'BEGIN {
    e = e1 < e2 ? e1 : e2; m = m1 < m2 ? m1 : m2
    printf "BENCH trace_mesh_bytes_per_tri %.1f bytes\n", (m - e) * 1024 / n }'
o1=$(peak mesh.scene 0); o2=$(peak mesh.scene 0)
awk -v e1="$e1" -v e2="$e2" -v m1="$o1" -v m2="$o2" -v n="$nt" 'BEGIN {
    e = e1 < e2 ? e1 : e2; m = m1 < m2 ? m1 : m2
    printf "BENCH trace_mesh_bytes_per_tri_one_bvh %.1f bytes\n", (m - e) * 1024 / n }'
sed 's/radius 5 grid 10/radius 9.9 grid 400/' "$W/mesh.scene" > "$W/speed.scene"
tms() {   # trace ms of speed.scene with LENSMAT_TRACE_CHUNK=$1 (empty: the default)
    (cd "$W" && printf 'scene\nspeed.scene\nn\n' | LENSMAT_TRACE_CHUNK=$1 "$LM" --trace -i /dev/stdin s.rec) |
        sed -n 's/^Build .* ms, trace \([0-9.e+]*\) ms.*/\1/p'
}
c1=$(tms ""); b1=$(tms 0); c2=$(tms ""); b2=$(tms 0); c3=$(tms ""); b3=$(tms 0)
echo "# in chunks: $c1 $c2 $c3 ms; one BVH: $b1 $b2 $b3 ms (load $(cut -d' ' -f1 /proc/loadavg))"
echo "$c1 $c2 $c3 $b1 $b2 $b3" | awk 'function med(a, b, c) { return a + b + c - (a > b ? (a > c ? a : c) : (b > c ? b : c)) - (a < b ? (a < c ? a : c) : (b < c ? b : c)) }
    { printf "BENCH trace_mesh_chunked_vs_one_bvh %.3f ratio\n", med($4, $5, $6) / med($1, $2, $3) }'
# the BVH path against bare Embree, per segment, on the scenes users trace
# (tests/trace/bench_mesh.c: trace_mesh_vs_raw_embree and its _alone, _mirror, _tir,
# _mix variants)
B=build/obj/trace_tests/bench_mesh
[ -x "$B" ] || { echo "bench_trace_mesh: $B not built (make bench builds it)" >&2; exit 1; }
"$B" ${BENCH_QUICK:+quick}
