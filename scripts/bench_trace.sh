#!/bin/sh
# bench_trace.sh -- the ray-tracing engine's figures (see tests/trace/bench_trace.c):
# full trace vs bare Embree, vs the seed's per-triangle loop on a 100 000-triangle
# cornea (loop timed on 200 segments and scaled), Mrays/s on all cores, 2-thread
# scaling, memory per million triangles, and the Cooke triplet f/4 workload (1e6
# rays, Fresnel on, one thread, median of 3 runs; peak RSS of a child process), and the
# power sums of 1e8 rays (issue 9).
# BENCH_QUICK=1: smaller.
B=build/obj/trace_tests/bench_trace
[ -x "$B" ] || { echo "bench_trace: $B not built (make bench builds it)" >&2; exit 1; }
if [ -n "$BENCH_QUICK" ]; then exec "$B" quick; else exec "$B"; fi
