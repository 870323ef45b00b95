#!/bin/sh
# bench_cornea.sh -- the cornea measurement's figures (tests/cornea/bench_cornea.c):
# recovered apex radius, mean K and cylinder axis errors of the issue-12 synthetic eye,
# and the table of scan points against plan/fit time and error (10 to 10 000 points),
# one thread.  BENCH_QUICK=1: 3 seeds per row instead of 10.
B=build/obj/cornea_tests/bench_cornea
[ -x "$B" ] || { echo "bench_cornea: $B not built (make bench builds it)" >&2; exit 1; }
echo "# bench_cornea on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores"
if [ -n "$BENCH_QUICK" ]; then exec "$B" quick; else exec "$B"; fi
