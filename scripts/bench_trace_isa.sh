#!/bin/sh
# bench_trace_isa.sh -- the Cooke triplet figure of the lens packets on each
# instruction set this processor runs (issue 13): `bench_trace isas` lists them,
# LENSMAT_ISA forces each in turn (scalar: rays one by one, the baseline), one thread,
# 1e6 rays, Fresnel on (tests/trace/bench_trace.c, triplet_isa).  Five rounds, each
# running every kernel back to back, so that the machine's drift hits all alike:
# BENCH trace_triplet_<isa>_mrays_per_s is the median of the five runs (wall clock),
# BENCH trace_triplet_<isa>_cpu_mrays_per_s the same per second of the tracing
# thread's CPU time (what other processes on a busy machine do not halve), and
# BENCH trace_triplet_<isa>_vs_scalar the median of the five ratios to scalar's run
# of the same round; BENCH trace_sse2_4lane_vs_2lane (and _cpu) the median ratio of
# the 4-lane base kernel (sse2x4: two SSE2 registers a vector; neonx4 on arm64) to the
# 2-lane one in the same round.
B=build/obj/trace_tests/bench_trace
[ -x "$B" ] || { echo "bench_trace_isa: $B not built (make bench builds it)" >&2; exit 1; }
isas=$("$B" isas) || exit 1
echo "# bench_trace_isa on: $(uname -m), $(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -1), $(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg); kernels this processor runs: $(echo $isas)"
runs=$(for r in 1 2 3 4 5; do
           for i in $isas; do echo "$r $(LENSMAT_ISA=$i "$B" isa)" || exit 1; done
       done) || exit 1
echo "$runs" | awk -v order="$(echo $isas)" '
    function median(a, n,   i, j, t) {      # sorts a[1..n]
        for (i = 2; i <= n; i++)
            for (j = i; j > 1 && a[j - 1] > a[j]; j--) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
        return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
    }
    { v[$2, $1] = $3; c[$2, $1] = $4; round[$1] = 1 }
    END {
        k = split(order, name, " ")
        for (i = 1; i <= k; i++) {
            n = 0; for (r in round) x[++n] = v[name[i], r]
            printf "BENCH trace_triplet_%s_mrays_per_s %.3f Mrays/s\n", name[i], median(x, n)
        }
        for (i = 1; i <= k; i++) {
            n = 0; for (r in round) x[++n] = c[name[i], r]
            printf "BENCH trace_triplet_%s_cpu_mrays_per_s %.3f Mrays/s\n", name[i], median(x, n)
        }
        for (i = 1; i <= k; i++) {
            if (name[i] == "scalar") continue
            n = 0; for (r in round) x[++n] = v[name[i], r] / v["scalar", r]
            printf "BENCH trace_triplet_%s_vs_scalar %.2f ratio\n", name[i], median(x, n)
        }
        # issue 23: four lanes on the base registers (sse2x4 / neonx4) over two, per round
        w = ("sse2x4", 1) in v ? "sse2" : ("neonx4", 1) in v ? "neon" : ""
        if (w != "") {
            n = 0
            for (r in round) { n++; x[n] = v[w "x4", r] / v[w, r]; y[n] = c[w "x4", r] / c[w, r] }
            printf "BENCH trace_sse2_4lane_vs_2lane %.2f ratio\n", median(x, n)
            printf "BENCH trace_sse2_4lane_vs_2lane_cpu %.2f ratio\n", median(y, n)
        }
    }'
