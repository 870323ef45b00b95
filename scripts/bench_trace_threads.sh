#!/bin/sh
# bench_trace_threads.sh -- one thread against two on the lens path and the BVH path,
# by wall clock and by CPU time (tests/trace/bench_threads.c): trace_threads_scaling_lens,
# trace_threads_scaling_bvh (from CPU time) and their _wall twins, with the CPU-seconds
# per thread and how much of the two cores the 2-thread runs got (the load).
B=build/obj/trace_tests/bench_threads
[ -x "$B" ] || { echo "bench_trace_threads: $B not built (make bench builds it)" >&2; exit 1; }
echo "# bench_trace_threads on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores"
exec "$B"
