#!/bin/sh
# bench_scan.sh -- the scan's machine time through the path users take (issue 19 item
# 6, doc/scan-time.md): lensmat --cornea-scan on the simulated chip with
# golden/rig/example.rig, 1000 points, issue 12's eye through full synthetic frames,
# BENCH cornea_scan1000_sim_s = the simulator's clock from the first move to the last
# pulse's end (simulated time: the same on any machine).  The baselines in the same
# run: the same rig stop and go (expose_moving no, 1 ms exposures, the planner's
# order), and the old example rig (git show d720c04:golden/rig/example.rig) stop and
# go in the planner's order.  Then the fixation-drift figures (tests/topo/t_drift.c:
# BENCH topo_drift_*).
L=./lensmat
D=build/obj/topo_tests/t_drift
[ -x "$L" ] || { echo "bench_scan: $L not built" >&2; exit 1; }
[ -x "$D" ] || { echo "bench_scan: $D not built (make bench builds it)" >&2; exit 1; }
O=build/bench/scan
mkdir -p "$O"
echo "# bench_scan on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg) (simulated time: the machine does not matter)"
answers() {     # answers RIG PATTERN MS SOURCE
    if [ "$4" = frames ]; then src='frames\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-'
    else src='model\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n14'; fi
    printf "biconic\n%s\nsim\n-\n%s\n%s\n1000\n12\n$src\n1\n0\n-\n" "$1" "$3" "$2"
}
scan() {        # scan NAME RIG PATTERN MS SOURCE: the record's Scan line
    answers "$2" "$3" "$4" "$5" > "$O/$1.in"
    "$L" --cornea-scan -i "$O/$1.in" "$O/$1.rec" > "$O/$1.out" 2> "$O/$1.err" ||
        { echo "bench_scan: $1 failed: $(head -1 "$O/$1.err")" >&2; return 1; }
    grep '^Scan on the machine' "$O/$1.rec"
}
simt() { sed -n 's/^Scan on the machine: .* order: \([0-9.]*\) s of machine time.*/\1/p' "$O/$1.rec"; }
scan fly golden/rig/example.rig rings 0.02 frames || exit 1
grep -E '^(Smear|Errors|Fixation|Dose)' "$O/fly.rec" | sed 's/^/# /'
sed 's/^expose_moving yes.*/expose_moving no/' golden/rig/example.rig > "$O/stopgo.rig"
scan stopgo "$O/stopgo.rig" spiral 1 model || exit 1
if git show d720c04:golden/rig/example.rig > "$O/old.rig" 2> /dev/null; then
    scan old "$O/old.rig" spiral 1 model || exit 1
    old=$(simt old)
else old=nan; fi
f=$(simt fly); s=$(simt stopgo)
echo "# 1000 points: on the fly $f s; the same rig stop and go $s s; the old example rig stop and go (planned order) $old s"
echo "BENCH cornea_scan1000_sim_s $f s"
echo "BENCH cornea_scan1000_stopgo_sim_s $s s"
echo "BENCH cornea_scan1000_oldrig_sim_s $old s"
echo "BENCH cornea_scan1000_fly_vs_stopgo $(awk -v a="$f" -v b="$s" 'BEGIN { printf "%.3f", a / b }') x"
# one rig for both the clinical zone and the fast scan: golden/rig/wide-zone.rig (the
# zone's geometry with the example's motors), the zone pattern over 8 mm, 1000
# targets, on the fly; the scan's own pass (the coarse passes before it are said too)
printf 'biconic\ngolden/rig/wide-zone.rig\nsim\n-\n0.02\nzone\n1000\n8\nmodel\n7.8\n-0.26\n0.75\n0\n0\n0\n0\n0\n0.04\n3.45\n1\n0\n-\n' > "$O/wide.in"
"$L" --cornea-scan -i "$O/wide.in" "$O/wide.rec" > "$O/wide.out" 2> "$O/wide.err" ||
    { echo "bench_scan: wide failed: $(head -1 "$O/wide.err")" >&2; exit 1; }
grep -E '^(Zone pass|Pattern zone|Scan on the machine|Coverage)' "$O/wide.rec" | sed 's/^/# wide-zone rig: /'
echo "BENCH cornea_scan1000_widezone_sim_s $(simt wide) s"
"$D" 1000 | grep -E '^(BENCH|#|FAIL)'
