#!/bin/sh
# bench_cornea_scan.sh -- the whole cornea measurement through the path users take
# (lensmat --cornea-scan: plan, trace, full synthetic 640x480 frames, centroids, fit,
# tracer check of the fitted cornea) on issue 12's eye (R 7.8, Q -0.26, 0.75 D with the
# rule, 0.2 mm decentration, 2 deg tilt), the example rig's steps, the imaging
# benchmark's spot and noise (0.04 px at 14 um pixels).  Prints the 1000-point time and
# its parts (median of 3 runs; the baseline in the same run: the same scan with the
# traced hit plus Gaussian noise instead of frames), the thread check (1 and 2 threads:
# the same record and report), and the table of error against run time from 10 to
# 10 000 points (RMS over seeds), written to build/bench/cornea_scan.tsv and plotted to
# build/bench/cornea_scan.png.  BENCH_QUICK=1: fewer seeds.
L=./lensmat
P=build/obj/cornea_tests/scan_plot
[ -x "$L" ] || { echo "bench_cornea_scan: $L not built" >&2; exit 1; }
O=build/bench/cornea_scan
mkdir -p "$O"
cpu=$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')
echo "# bench_cornea_scan on: $cpu, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
answers() {     # answers N SOURCE SEED REPORT: no cone; REPORT a name (no maps) or -
    if [ "$2" = frames ]; then src='frames\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-'
    else src='model\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n14'; fi
    printf "biconic\n-\nspiral\n%s\n12\n$src\n%s\n0\n%s\n" "$1" "$3" "$4"
    [ "$4" = - ] || echo n
}
scan() {        # scan NAME N SOURCE SEED [REPORT]: the Times line's numbers
    answers "$2" "$3" "$4" "${5:--}" > "$O/$1.in"
    "$L" --cornea-scan -i "$O/$1.in" "$O/$1.rec" > "$O/$1.out" 2> "$O/$1.err" ||
        { echo "bench_cornea_scan: $1 failed: $(head -1 "$O/$1.err")" >&2; return 1; }
}
tline() { sed -n 's/^Times (\([0-9]*\) threads): plan \([0-9.]*\) s, machine [0-9.]* s, trace + frames + centroids \([0-9.]*\) s, fit \([0-9.]*\) s, tracer check \([0-9.]*\) s, total \([0-9.]*\) s (CPU \([0-9.]*\) s).*/\1 \2 \3 \4 \5 \6 \7/p' "$O/$1.out"; }
median3() { sort -n | sed -n 2p; }
# ---- 1000 points, three runs each way ----
for i in 1 2 3; do
    t0=$(date +%s.%N); scan f$i 1000 frames 1 || exit 1; t1=$(date +%s.%N)
    echo "$(tline f$i) $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')" >> "$O/f.times.$$"
    scan m$i 1000 model 1 || exit 1
    tline m$i >> "$O/m.times.$$"
done
med=$(awk '{ print $6, $0 }' "$O/f.times.$$" | sort -n | sed -n 2p | cut -d' ' -f2-)
cmed=$(awk '{ print $7 }' "$O/f.times.$$" | median3)
mmed=$(awk '{ print $6 }' "$O/m.times.$$" | median3)
rm -f "$O/f.times.$$" "$O/m.times.$$"
set -- $med
echo "# 1000 points, $1 threads (median of 3 runs): plan $2 s, trace + frames + centroids $3 s, fit $4 s, tracer check $5 s, measurement $6 s (CPU $cmed s over both cores), whole command $8 s (modules loaded, OpenCV's 70-250 ms included)"
echo "BENCH cornea_scan1000_s $6 s"
echo "BENCH cornea_scan1000_plan_s $2 s"
echo "BENCH cornea_scan1000_frames_s $3 s"
echo "BENCH cornea_scan1000_fit_s $4 s"
echo "BENCH cornea_scan1000_check_s $5 s"
echo "BENCH cornea_scan1000_cpu_s $cmed s"
echo "BENCH cornea_scan1000_command_s $8 s"
echo "BENCH cornea_scan1000_model_s $mmed s"
echo "BENCH cornea_scan1000_frames_vs_model $(awk -v a="$6" -v b="$mmed" 'BEGIN { printf "%.2f", a / b }') x"
# ---- the same record and report whatever the thread count ----
LENSMAT_THREADS=1 scan th1 1000 frames 1 th1 && mv th1.txt "$O/th1.rep" && mv th1.csv "$O/th1.csv"
LENSMAT_THREADS=2 scan th2 1000 frames 1 th1 && mv th1.txt "$O/th2.rep" && mv th1.csv "$O/th2.csv"
rm -f th1.json
same=0
cmp -s "$O/th1.rec" "$O/th2.rec" && cmp -s "$O/th1.rep" "$O/th2.rep" &&
    cmp -s "$O/th1.csv" "$O/th2.csv" && same=1
set -- $(tline th1)
echo "# 1 thread: measurement $6 s (frames $3 s); record and report identical to 2 threads: $same"
echo "BENCH cornea_scan1000_1thread_s $6 s"
echo "BENCH cornea_scan_threads_identical $same bool"
# ---- error against run time ----
if [ -n "$BENCH_QUICK" ]; then seeds="1 2"; mid="1 2"; big="1"
else seeds="1 2 3 4 5 6 7 8 9 10"; mid="1 2 3 4 5"; big="1 2"; fi
T=build/bench/cornea_scan.tsv
echo "# points	cpu_s	R_err_um	Km_err_D	R_sd_um	Km_sd_D	wall_s	fitted	seeds" > "$T"
for n in 10 30 100 300 1000 3000 10000; do
    ss=$seeds; [ "$n" -ge 1000 ] && ss=$mid; [ "$n" -ge 10000 ] && ss=$big
    : > "$O/row"
    for s in $ss; do
        scan e$n.$s $n frames $((100 + s)) || continue
        r=$(sed -n 's/^Errors: R \([-0-9.]*\) um, mean K \([-0-9.]*\) D.*/\1 \2/p' "$O/e$n.$s.rec")
        sd=$(sed -n 's/^apex radius R [0-9.]* +- \([0-9.]*\) mm.*/\1/p' "$O/e$n.$s.rec")
        ksd=$(sed -n 's/^mean K [0-9.]* +- \([0-9.]*\) D.*/\1/p' "$O/e$n.$s.rec")
        fit=$(sed -n 's/^Spots: \([0-9]*\) fitted.*/\1/p' "$O/e$n.$s.rec")
        set -- $(tline e$n.$s)
        echo "$7 $r $sd $ksd $fit $6" >> "$O/row"
        rm -f "$O/e$n.$s.rec" "$O/e$n.$s.out"
    done
    awk -v n=$n '{ t += $1; r += $2 * $2; k += $3 * $3; sr += $4; sk += $5; f += $6; w += $7; m++ }
        END { if (m) printf "%d\t%.4f\t%.3f\t%.5f\t%.3f\t%.5f\t%.4f\t%d\t%d\n", n, t / m, sqrt(r / m),
              sqrt(k / m), 1e3 * sr / m, sk / m, w / m, f / m, m }' "$O/row" >> "$T"
done
echo "# error against run time (spiral to 12 deg, frames 640x480 at 14 um, RMS over seeds; sd: the fit's own; cpu: the measurement's CPU seconds, both threads; wall: its wall clock, with whatever else the machine runs):"
column -t "$T" 2>/dev/null || cat "$T"
awk '!/^#/ { printf "BENCH cornea_scan_%d_cpu_s %s s\nBENCH cornea_scan_%d_radius_err_um %s um\nBENCH cornea_scan_%d_power_err_D %s D\n", $1, $2, $1, $3, $1, $4 }' "$T"
if [ -x "$P" ]; then
    "$P" "$T" build/bench/cornea_scan.png "issue 12 eye, spiral to 12 deg, 640x480 frames at 14 um (0.04 px), biconic + pose fit; $cpu, $(nproc) cores" | tail -1
fi
