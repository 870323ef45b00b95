#!/bin/sh
# bench_trace_out.sh -- what writing every detector hit costs (issue 23): the Cooke
# triplet scene of bench_trace_scene.sh (1128 x 1128 collimated grid = 999 332 rays,
# Fresnel on, reflections off, `threads 1`; nearly every ray reaches the detector)
# traced by `lensmat --trace` (the path users take) with no hit output, with
# `output hits F.csv` (shortest round-trip numbers), F.npy, F.h5 and F.csv csv17 (the
# "%.17g" CSV of before).  Each round runs, back to back: the same scene with a 1-ray
# grid (lensmat's start, the module load, the scene read: what every run has), no
# output, CSV, .npy, HDF5; 5 rounds (3 with BENCH_QUICK), csv17 once.  Each run is
# timed whole (wall clock and the process's CPU time, every thread's, from wait4), so
# the writer's last chunk, the .npy header, the HDF5 image and the rename are in it;
# the 1-ray run's times are taken off both sides:
#   cost = (run with the output - 1-ray run) / (run without output - 1-ray run)
# per round, the median of the rounds (a round's runs see the same load).
#   trace_hits_csv_cost    wall-clock cost of every hit as CSV (<= 2)
#   trace_hits_npy_cost    the same for .npy (<= 1.2)
#   trace_hits_h5_cost     the same for HDF5 (tables assembled in memory, written once)
#   trace_hits_csv17_cost  the CSV of before, for comparison
#   trace_hits_csv_mrays_per_s  rays/s with every hit written as CSV (wall)
#   trace_hits_{csv,npy,h5}_cpu_cost  the same ratios in CPU time: what the output
#                          costs in work, whatever else the machine is doing.  The
#                          CSV is formatted by one thread beside the trace's (the
#                          scene's thread count) and by the trace's own thread when
#                          it would wait: on a machine with a core to spare the wall
#                          figure is below the CPU one; on a full machine they meet.
# BENCH_QUICK=1: a 400 x 400 grid.
set -e
LM=$(pwd)/lensmat
[ -x "$LM" ] && [ -f build/lib/lensmat-trace.so ] || { echo "bench_trace_out: lensmat or its trace module not built" >&2; exit 1; }
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
isa=$(grep -m1 -o -w 'avx512f' /proc/cpuinfo || grep -m1 -o -w 'avx2' /proc/cpuinfo || uname -m)
echo "# bench_trace_out on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, $isa, load $(cut -d' ' -f1-3 /proc/loadavg); threads 1; outputs to $(df -PT "$W" | awk 'NR == 2 { print $2 }')"
GRID=${BENCH_QUICK:+400}
ROUNDS=${BENCH_QUICK:+3}
scene() {
awk -v grid="$1" 'BEGIN {
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
    print "reflections off\nthreads 1" }'
}
scene "${GRID:-1128}" > "$W/base"
for k in one none csv npy h5 csv17; do
    cp "$W/base" "$W/$k.scene"
    case $k in
    one) scene 1 > "$W/$k.scene"; echo "output hits hits.csv" >> "$W/$k.scene" ;;
    none) ;;
    csv17) echo "output hits hits17.csv csv17" >> "$W/$k.scene" ;;
    *) echo "output hits hits.$k" >> "$W/$k.scene" ;;
    esac
    printf 'scene\n%s.scene\nn\n' "$k" > "$W/in_$k"
done
# one lensmat run: "wall_s cpu_s trace_ms rays hits" (CPU: user + system of the
# process and all its threads, from wait4)
cat > "$W/run.py" <<'EOF'
import os, re, sys, time
lm, k = sys.argv[1], sys.argv[2]
out = os.open("out", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
t0 = time.monotonic()
pid = os.fork()
if pid == 0:
    os.dup2(out, 1)
    os.execv(lm, [lm, "--trace", "-i", "in_" + k, "r.rec"])
_, st, ru = os.wait4(pid, 0)
wall = time.monotonic() - t0
if st != 0:
    sys.exit("lensmat failed: " + k)
txt = open("out").read()
rays = int(re.search(r"^Rays traced: (\d+)", txt, re.M).group(1))
hits = int(re.search(r"^Detector hits: (\d+)", txt, re.M).group(1))
ms = float(re.search(r"trace ([0-9.e+]+) ms", txt).group(1))
print("%.6f %.6f %g %d %d" % (wall, ru.ru_utime + ru.ru_stime, ms, rays, hits))
EOF
run() {
    (cd "$W" && "$PY" run.py "$LM" "$1" && rm -f hits.* hits17.csv) >> "$W/t_$1"
}
for i in $(seq "${ROUNDS:-5}"); do
    for k in one none csv npy h5; do run $k; done
done
run csv17
# the per-round costs (field f: 1 wall, 2 CPU), then their median
costs() {
    paste -d' ' "$W/t_one" "$W/t_none" "$W/t_$1" | awk -v f="$2" '{
        o = $(f); n = $(5 + f); x = $(10 + f); print (x - o) / (n - o) }' | sort -g |
        awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}
med() { cut -d' ' -f"$2" "$W/t_$1" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
read -r _ _ _ rays hits < "$W/t_none"
echo "# $rays rays, $hits hits; medians, wall s: 1-ray $(med one 1), none $(med none 1), csv $(med csv 1), npy $(med npy 1), h5 $(med h5 1), csv17 $(med csv17 1); CPU s: 1-ray $(med one 2), none $(med none 2), csv $(med csv 2), npy $(med npy 2), h5 $(med h5 2), csv17 $(med csv17 2); lensmat's own trace ms: none $(med none 3), csv $(med csv 3), npy $(med npy 3)"
echo "# load at the end $(cut -d' ' -f1-3 /proc/loadavg)"
# csv17 ran once: its cost against the medians
c17=$(awk -v o="$(med one 1)" -v n="$(med none 1)" -v x="$(med csv17 1)" 'BEGIN { print (x - o) / (n - o) }')
awk -v c="$(costs csv 1)" -v p="$(costs npy 1)" -v h="$(costs h5 1)" -v o="$c17" \
    -v w="$(med csv 1)" -v w1="$(med one 1)" -v r="$rays" 'BEGIN {
    printf "BENCH trace_hits_csv_cost %.2f ratio\n", c
    printf "BENCH trace_hits_npy_cost %.2f ratio\n", p
    printf "BENCH trace_hits_h5_cost %.2f ratio\n", h
    printf "BENCH trace_hits_csv17_cost %.2f ratio\n", o
    printf "BENCH trace_hits_csv_mrays_per_s %.3f Mrays/s\n", r / (w - w1) / 1e6 }'
awk -v c="$(costs csv 2)" -v p="$(costs npy 2)" -v h="$(costs h5 2)" 'BEGIN {
    printf "BENCH trace_hits_csv_cpu_cost %.2f ratio\n", c
    printf "BENCH trace_hits_npy_cpu_cost %.2f ratio\n", p
    printf "BENCH trace_hits_h5_cpu_cost %.2f ratio\n", h }'
