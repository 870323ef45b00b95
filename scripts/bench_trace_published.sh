#!/bin/sh
# bench_trace_published.sh -- published lenses (README "Published lenses"): the
# tracer on Sasian's Cooke triplet, with bench_trace's triplet as the second row
# (tests/trace/bench_published.c), and the Seidel sums against ray-optics' published
# table for the same lens (tests/unit_published.c bench).  BENCH_QUICK=1: fewer rays.
B=build/obj/trace_tests/bench_published
U=build/obj/unit_published
[ -x "$B" ] || { echo "bench_trace_published: $B not built (make bench builds it)" >&2; exit 1; }
[ -x "$U" ] || { echo "bench_trace_published: $U not built (make bench builds it)" >&2; exit 1; }
echo "bench_trace_published on $(uname -m),$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2), $(nproc) cpus"
"$B" || exit 1
LENSMAT_LIBDIR=build/lib "$U" bench
