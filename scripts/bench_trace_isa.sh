#!/bin/sh
# bench_trace_isa.sh -- the Cooke triplet figure of the lens packets on each
# instruction set this processor runs (issue 13): `bench_trace isas` lists them,
# LENSMAT_ISA forces each in turn (scalar: rays one by one, the baseline), one thread,
# 1e6 rays, Fresnel on, median of three (tests/trace/bench_trace.c, triplet_isa).
# Prints BENCH trace_triplet_<isa>_mrays_per_s and, against scalar measured in the
# same run, BENCH trace_triplet_<isa>_vs_scalar.
B=build/obj/trace_tests/bench_trace
[ -x "$B" ] || { echo "bench_trace_isa: $B not built (make bench builds it)" >&2; exit 1; }
isas=$("$B" isas) || exit 1
echo "# bench_trace_isa on: $(uname -m), $(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -1), $(nproc) cores; kernels this processor runs: $(echo $isas)"
out=$(for i in $isas; do LENSMAT_ISA=$i "$B" isa || exit 1; done) || exit 1
echo "$out"
echo "$out" | awk '{ v[$2] = $3 } END {
    s = v["trace_triplet_scalar_mrays_per_s"]
    for (k in v) if (k != "trace_triplet_scalar_mrays_per_s" && s > 0) {
        n = k; sub(/_mrays_per_s$/, "_vs_scalar", n)
        printf "BENCH %s %.2f ratio\n", n, v[k] / s
    } }' | sort
