#!/bin/sh
# bench_design.sh -- the lens-design figures (doc/design.md): Sasian's triplet
# optimised from radii perturbed by 10 % (doc/design/sasian-start.rx) against the
# published design under the same merit (doc/design/sasian-triplet.rx's operands at
# its start), the Monte Carlo tolerancing rate on one core (one process), with tilts
# too, and the tilt sensitivities against a closed form (tests/design/t_toltilt.c).
# Medians of 3 runs.  Prints BENCH lines and the machine it ran on.
TOP=$(cd "$(dirname "$0")/.." && pwd)
L=$TOP/lensmat
[ -x "$L" ] && [ -f "$TOP/build/lib/lensmat-design.so" ] || { echo "bench_design: build first (make)" >&2; exit 1; }
D=$(mktemp -d)
trap 'rm -rf "$D"' EXIT
cd "$D" && ln -s "$TOP/doc" doc
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
cpu=$(awk -F': ' '/model name/ { print $2; exit }' /proc/cpuinfo)
echo "# bench_design on $cpu, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"

printf 'doc/design/sasian-triplet.rx\n-\n1\npub.rx\n' > pub.in
"$L" --optimise -i pub.in pub.rec > /dev/null || exit 1
worst() { awk -v sect="$2" '$0 ~ sect { on = 1 } on && /^  iteration/ { on = 0 }
          on && $1 == "rms" && $2 == "field" { if ($6 > w) w = $6 } END { print w }' "$1"; }
wp=$(worst pub.rec 'operands \\(target')
for i in 1 2 3; do
    rm -f sasian-optimised.rx
    "$L" --optimise --example o$i.rec > o$i.out || exit 1
    awk '/ s, .* merit evaluations/ { print $1 }' o$i.out >> secs
done
wo=$(worst o1.rec 'operands at the end')
ev=$(awk '/ s, .* merit evaluations/ { print $3 }' o1.out)
echo "# published worst-field RMS $wp mm, optimised $wo mm ($ev merit evaluations)"
awk -v a="$wo" -v b="$wp" 'BEGIN { printf "BENCH opt_triplet_rms_ratio %.4f ratio\n", a / b }'
printf 'BENCH opt_triplet_s %s s\n' "$(median < secs)"
# the same ratio with 16 rings x 32 arms (spots converged to 1e-5): not an artefact of
# the merit's 9 rays a field
printf 'vary t 6\ntarget rms 0\ndesign rings 16 arms 32\n' > dense.mf
for l in sasian-optimised doc/design/sasian-triplet; do
    sed '/^vary\|^target\|^min\|^design/d' $l.rx > dense-in.rx
    printf 'dense-in.rx\ndense.mf\n1\ndense-out.rx\n' > dense.in
    rm -f dense-out.rx
    "$L" --optimise -i dense.in dense.rec > /dev/null || exit 1
    awk '/operands \(target/ { on = 1 } /^  iteration/ { on = 0 } on && $1 == "rms" { if ($6 > w) w = $6 } END { print w }' dense.rec >> dense.txt
done
awk 'NR == 1 { a = $1 } NR == 2 { b = $1 } END { printf "BENCH opt_triplet_rms_ratio_dense %.4f ratio\n", a / b }' dense.txt
# what one merit evaluation costs (81 aimed rays, 3 paraxial set-ups): the floor the
# time above is made of
awk -v s="$(median < secs)" -v e="$ev" 'BEGIN { printf "BENCH opt_triplet_eval_ms %.3f ms\n", 1000 * s / e }'
# the same run with geodesic acceleration (design method lmaccel)
{ cat doc/design/sasian-start.rx; echo 'design method lmaccel'; } > acc.rx
printf 'acc.rx\n-\n200\nacc-out.rx\n' > acc.in
for i in 1 2 3; do
    rm -f acc-out.rx
    "$L" --optimise -i acc.in acc$i.rec > acc$i.out || exit 1
    awk '/ s, .* merit evaluations/ { print $1 }' acc$i.out >> asecs
done
printf 'BENCH opt_triplet_lmaccel_s %s s\n' "$(median < asecs)"

N=2000
printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian.tol\nmc\n%d\n1\n1\nuniform\nbfd\n25\n-\n' $N > mc.in
for i in 1 2 3; do
    t0=$(date +%s.%N)
    taskset -c 0 "$L" --tolerance -i mc.in mc.rec > /dev/null 2>&1 || "$L" --tolerance -i mc.in mc.rec > /dev/null || exit 1
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" -v n=$N 'BEGIN { print n / (b - a) }' >> rate
done
printf 'BENCH tol_mc_lenses_per_s %.1f lenses/s\n' "$(median < rate)"
# the same with tilts and decentres (doc/design/sasian-tilt.tol: 41 tolerances, a
# coordinate-break pair per perturbed surface or element, the whole pupil traced)
printf 'doc/design/sasian-triplet.rx\ndoc/design/sasian-tilt.tol\nmc\n%d\n1\n1\nuniform\nbfd\n25\n-\n' $N > mct.in
for i in 1 2 3; do
    t0=$(date +%s.%N)
    taskset -c 0 "$L" --tolerance -i mct.in mct.rec > /dev/null 2>&1 || "$L" --tolerance -i mct.in mct.rec > /dev/null || exit 1
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" -v n=$N 'BEGIN { print n / (b - a) }' >> trate
done
printf 'BENCH tol_mc_tilt_lenses_per_s %.1f lenses/s\n' "$(median < trate)"
# tilt and decentre sensitivities (the boresight of 28 of them on Sasian's triplet)
# against the first-order closed form of tests/design/t_toltilt.c
T=$TOP/build/obj/design_tests/t_toltilt
if [ -x "$T" ]; then
    (cd "$TOP" && "$T") | awk '/^closed form: worst relative error/ { printf "BENCH tol_tilt_sens_rel_err %s ratio\n", $NF }'
fi
