#!/bin/sh
# bench.sh -- every benchmark: runs scripts/bench_*.sh in order; each prints
# "BENCH <name> <value> <unit>" lines.  Figures are medians of repeated runs on this
# machine, with the baseline measured in the same run.
status=0
for b in scripts/bench_*.sh; do
    [ -f "$b" ] || continue
    sh "$b" || { echo "bench: $b failed" >&2; status=1; }
done
exit $status
