#!/bin/sh
# bench_rig.sh -- the cornea rig's geometry figures (tests/rig/bench_geom.c): exactness
# of the traced solutions, quantised landing error of the example rig, the table of
# landing error against steps per degree / per mm, and points planned per second
# (one thread).  BENCH_QUICK=1: fewer repetitions of the speed runs.
B=build/obj/rig_tests/bench_geom
[ -x "$B" ] || { echo "bench_rig: $B not built (make bench builds it)" >&2; exit 1; }
echo "# bench_rig on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores"
# the safety figures (tests/rig/bench_safety.c, doc/rig-safety.md): simulated time, so
# the same on any machine; BENCH rig_interlock_motion_stop_ms, rig_dose_mpe_fraction
S=build/obj/rig_tests/bench_safety
[ -x "$S" ] || { echo "bench_rig: $S not built (make bench builds it)" >&2; exit 1; }
"$S" golden/rig/example.rig || exit 1
# the scan time (tests/rig/bench_scan.c, doc/scan-time.md): simulated time of 1000
# spiral points, ordered and in the spiral's own order, stop and go (BENCH rig_scan1000_*;
# cornea_scan1000_sim_s is scripts/bench_scan.sh's, through --cornea-scan)
T=build/obj/rig_tests/bench_scan
[ -x "$T" ] || { echo "bench_rig: $T not built (make bench builds it)" >&2; exit 1; }
"$T" golden/rig/example.rig 1000 1.8 1 || exit 1
# ... and on the wide-zone rig (golden/rig/wide-zone.rig: the clinical zone's
# geometry with the example's motors), the same 1000 points to 1.8 deg
"$T" golden/rig/wide-zone.rig 1000 1.8 1 widezone || exit 1
if [ -n "$BENCH_QUICK" ]; then exec "$B" quick; else exec "$B"; fi
