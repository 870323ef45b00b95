#!/bin/sh
# bench_rig_hw.sh -- the rig machine's step timing (tests/rig/bench_step_jitter.c):
# p99 lateness of the STEP edges of a 10 s move at 2 kHz on the real clock with a
# do-nothing chip, SCHED_FIFO and mlockall when permitted, against a bare
# clock_nanosleep loop on the same deadlines in the same run; and what a scan point
# costs before the motors turn (tests/rig/bench_plan.c: solve, quantise, plan,
# forward check).  BENCH_QUICK=1: a 2 s move.
B=build/obj/rig_tests/bench_step_jitter
[ -x "$B" ] || { echo "bench_rig_hw: $B not built (make bench builds it)" >&2; exit 1; }
echo "# machine: $(uname -srm), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
P=build/obj/rig_tests/bench_plan
[ -x "$P" ] || { echo "bench_rig_hw: $P not built (make bench builds it)" >&2; exit 1; }
"$P" golden/rig/example.rig || exit 1
if [ -n "$BENCH_QUICK" ]; then exec "$B" 2; else exec "$B" 10; fi
