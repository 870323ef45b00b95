#!/bin/sh
# bench_pupil.sh -- the cost of rays aimed at the stop (tests/trace/bench_aim.c):
# aimed rays a second, against tracing the same rays once, rays traced per aimed ray,
# the worst Newton steps and stop residual (Cooke triplet, 20 degrees, one thread).
B=build/obj/trace_tests/bench_aim
[ -x "$B" ] || { echo "bench_pupil: $B not built (make bench builds it)" >&2; exit 1; }
echo "# machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; one thread"
exec "$B"
