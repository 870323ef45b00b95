#!/bin/sh
# bench_classic.sh -- the classic dialogue's start-up and replay cost.  Replays the
# convex-lens reference session (golden/cases/convex_thin_doc.in) 200 times and
# compares the median with a trivial C program that reads the same input and writes
# a record of the same size (the floor for process start-up), and with the original
# program (the transcribed listing, built from ../shared).
set -e
N=${BENCH_RUNS:-200}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
IN=$(pwd)/golden/cases/convex_thin_doc.in
R=build/bench/benchrun
./lensmat "$W/size.rec" < "$IN" > /dev/null
SIZE=$(wc -c < "$W/size.rec")
ours=$($R "$N" "$IN" "$(pwd)/lensmat" "$W/a.rec")
base=$($R "$N" "$IN" "$(pwd)/build/bench/baseline" "$W/b.rec" "$SIZE")
echo "BENCH classic_replay_ms $ours ms"
echo "BENCH classic_baseline_ms $base ms"
awk -v a="$ours" -v b="$base" 'BEGIN { printf "BENCH classic_vs_c_baseline %.2f ratio\n", a / b }'
if [ -x build/original/lensmat ]; then
    orig=$($R "$N" "$IN" "$(pwd)/build/original/lensmat" "$W/o.rec")
    echo "BENCH classic_original_ms $orig ms"
    awk -v a="$ours" -v b="$orig" 'BEGIN { printf "BENCH classic_vs_original %.2f ratio\n", a / b }'
fi
