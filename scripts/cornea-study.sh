#!/bin/sh
# cornea-study.sh -- the many-eyes accuracy study (issue 12 section 5): M simulated
# eyes drawn from a stated population, each an independent `lensmat --cornea-scan`
# run from its own answers file (so each replays exactly from its record), fanned out
# with GNU parallel over this machine's cores or several machines (--sshlogin), the
# reports collected into one table (DIR/study.tsv), the error percentiles per
# parameter (DIR/percentiles.tsv, printed) and one plot (DIR/study.png).
#
#     scripts/cornea-study.sh [-M EYES] [-s SEED] [-p POINTS] [-j JOBS] [-o DIR]
#                             [-m MODEL] [-S SSHLOGIN]
#
# Population (seeded; the eyes' answers are written first, then run):
#   R      mean apex radius  N(7.80, 0.25) mm, clipped to 7.0 .. 8.6
#   Q      conic constant    N(-0.26, 0.18), clipped to -0.9 .. 0.3
#   cyl    corneal cylinder  |N(0, 0.9)| D, clipped to 4
#   axis   flat meridian     with the rule 60 % (N(0, 12) deg), against 25 %
#                            (N(90, 12)), oblique 15 % (uniform 0 .. 180)
#   dx dy  decentration      N(0, 0.15) mm each, clipped to +-0.5
#   tx ty  tilt              N(0, 1.5) deg each, clipped to +-5
#   noise  centroid noise    uniform 0.02 .. 0.08 px (5 um pixels)
#   scan   POINTS points (300) over 12 deg, a biconic fit (-m to change), seed per eye
# Several machines: lensmat built or installed at the same path on each (LENSMAT,
# default this tree's ./lensmat); -S takes parallel's --sshlogin list (e.g.
# ":,4/user@host2"); each eye's answers go out and its record, report and output come
# back (--trc, by rsync over ssh: both needed here and on every host, with perl); on
# a host they sit in the login folder while the eye runs and are removed after.
# PARALLEL_SSH names another ssh command (tests/cornea/fake-ssh: hosts faked here).
set -e
TOP=$(cd "$(dirname "$0")/.." && pwd)
LENSMAT=${LENSMAT:-$TOP/lensmat}
PLOT=${STUDY_PLOT:-$TOP/build/obj/cornea_tools/study_plot}
M=20 SEED=1 POINTS=300 JOBS=0 DIR=cornea-study MODEL=biconic SSH=""
while getopts "M:s:p:j:o:m:S:h" o; do
    case $o in
    M) M=$OPTARG ;; s) SEED=$OPTARG ;; p) POINTS=$OPTARG ;; j) JOBS=$OPTARG ;;
    o) DIR=$OPTARG ;; m) MODEL=$OPTARG ;; S) SSH=$OPTARG ;;
    *) sed -n '2,27p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
    esac
done
case $M in ''|*[!0-9]*) echo "$0: -M wants a whole number of eyes" >&2; exit 2 ;; esac
case $SEED$POINTS in *[!0-9]*) echo "$0: -s and -p want whole numbers" >&2; exit 2 ;; esac
[ "$M" -ge 1 ] || { echo "$0: -M must be at least 1" >&2; exit 2; }
command -v parallel >/dev/null 2>&1 && parallel --version 2>/dev/null | grep -q 'GNU parallel' ||
    { echo "$0: GNU parallel is not installed (scripts/install-deps.sh installs it)" >&2; exit 3; }
[ -x "$LENSMAT" ] || { echo "$0: $LENSMAT not built (run make)" >&2; exit 3; }
if [ -n "$SSH" ] && [ "$SSH" != : ]; then
    command -v rsync >/dev/null 2>&1 ||
        { echo "$0: -S needs rsync (parallel sends the eyes' files with it; scripts/install-deps.sh installs it)" >&2; exit 3; }
fi
mkdir -p "$DIR"
cd "$DIR"
# The tables as lensmat writes files (doc/outputs.md): made in a unique temporary
# beside the name, with a plain create's modes, then renamed over a regular file (or
# a link's target); a device or FIFO there is written in place, never replaced.
part() { t=$(mktemp "$1.part.XXXXXX") && chmod "$(printf '%o' $((0666 & ~$(umask))))" "$t" && echo "$t"; }
put() {
    t=$2; [ -L "$t" ] && t=$(readlink -f -- "$t")
    if [ -e "$t" ] && [ ! -f "$t" ]; then cat "$1" > "$t" && rm -f "$1"; else mv -f "$1" "$t"; fi
}
rm -f eye-*.in eye-*.rec eye-*.txt eye-*.csv eye-*.json eye-*.out joblog.txt
# an earlier study's tables go; a link or a device the user put there stays
for f in study.tsv percentiles.tsv; do [ -f "$f" ] && [ ! -L "$f" ] && rm -f "$f"; done

# 1. the population: one answers file per eye (awk's generator, seeded)
awk -v M="$M" -v seed="$SEED" -v pts="$POINTS" -v model="$MODEL" '
function gauss() { return sqrt(-2 * log(1 - rand())) * cos(6.283185307179586 * rand()) }
function clip(v, lo, hi) { return v < lo ? lo : v > hi ? hi : v }
BEGIN {
    srand(seed)
    for (i = 1; i <= M; i++) {
        R = clip(7.8 + 0.25 * gauss(), 7.0, 8.6)
        Q = clip(-0.26 + 0.18 * gauss(), -0.9, 0.3)
        cyl = clip(sqrt((0.9 * gauss()) ^ 2), 0, 4)
        u = rand()
        if (u < 0.60) ax = 12 * gauss(); else if (u < 0.85) ax = 90 + 12 * gauss(); else ax = 180 * rand()
        ax = ax < 0 ? ax + 180 : ax >= 180 ? ax - 180 : ax
        dx = clip(0.15 * gauss(), -0.5, 0.5); dy = clip(0.15 * gauss(), -0.5, 0.5)
        tx = clip(1.5 * gauss(), -5, 5); ty = clip(1.5 * gauss(), -5, 5)
        noise = 0.02 + 0.06 * rand()
        f = sprintf("eye-%04d.in", i)
        # the answers in --cornea-scan order: model, rig (-: the example), pattern,
        # points, zone, spots from the model, the eye, noise, pitch, seed, no cone,
        # the report name, no maps
        printf "%s\n-\nspiral\n%d\n12\nmodel\n%.4f\n%.4f\n%.4f\n%.2f\n%.4f\n%.4f\n%.3f\n%.3f\n%.4f\n5\n%d\n0\neye-%04d\nn\n",
               model, pts, R, Q, cyl, ax, dx, dy, tx, ty, noise, seed * 100000 + i, i > f
        close(f)
    }
}'

# 2. the eyes, independent jobs under GNU parallel (no home-made scheduler)
set -- --jobs "${JOBS:-0}" --halt never --joblog joblog.txt
[ "$JOBS" = 0 ] && set -- --jobs 100% --halt never --joblog joblog.txt
if [ -n "$SSH" ]; then
    set -- "$@" --sshlogin "$SSH" --trc '{.}.rec' --trc '{.}.txt' --trc '{.}.csv' --trc '{.}.json' --trc '{.}.out'
fi
t0=$(date +%s.%N)
# parallel runs in the background so that a signal reaches this script at once (sh
# runs a trap only after the foreground command ends); the trap passes SIGTERM on to
# parallel, which stops its running jobs (each lensmat leaves no half-written file),
# waits for it and removes this script's own partial tables.
ls eye-*.in > eyes.list
parallel "$@" "'$LENSMAT' --cornea-scan {.}.rec < {} > {.}.out 2>&1" < eyes.list &
par=$!
study_stop() {
    trap '' INT TERM HUP
    kill -TERM "$par" 2> /dev/null || true
    wait "$par" 2> /dev/null || true   # (set -e: parallel's non-zero status must not end the trap)
    rm -f eyes.list "${tsv:-}" "${pct:-}"
    done_n=$(awk 'NR > 1 && $7 == 0' joblog.txt 2> /dev/null | wc -l)
    echo "$0: interrupted ($1): the running eyes were stopped; $done_n of $M eyes had finished (their files are in $DIR)" >&2
    exit "$2"
}
trap 'study_stop SIGINT 130' INT
trap 'study_stop SIGTERM 143' TERM
trap 'study_stop SIGHUP 129' HUP
wait "$par" || true
trap - INT TERM HUP
rm -f eyes.list
t1=$(date +%s.%N)
failed=$(awk 'NR > 1 && $7 != 0' joblog.txt | wc -l)

# 3. one table: the truth, the errors and the reported uncertainties of every eye
cols="true_R true_Q true_cyl true_dx true_dy true_tilt_x true_tilt_y scan_noise"
errs="err_R err_R_flat err_R_steep err_Q err_Km err_cyl err_axis err_dx err_dy err_tilt_x err_tilt_y"
tsv=$(part study.tsv)
trap 'rm -f "$tsv" "${pct:-}"' EXIT
{
    printf 'eye'
    for c in $cols; do printf '\t%s' "$c"; done
    for c in $errs; do printf '\t%s\tsd_%s' "$c" "${c#err_}"; done
    printf '\tzKm\tpoor\tundetermined\n'
    for f in eye-*.csv; do
        [ -e "$f" ] || continue
        awk -F, -v eye="${f%.csv}" -v cols="$cols" -v errs="$errs" '
        { v[$1] = $2; s[$1] = $3 } $1 == "undetermined" { und = und (und ? ";" : "") $2 }
        END {
            printf "%s", eye
            n = split(cols, c, " "); for (i = 1; i <= n; i++) printf "\t%s", v[c[i]]
            n = split(errs, e, " "); for (i = 1; i <= n; i++) printf "\t%s\t%s", v[e[i]], s[e[i]]
            printf "\t%s\t%s\t%s\n", v["zKm"], v["poor_fit"], und == "" ? "-" : und
        }' "$f"
    done
} > "$tsv"
neyes=$(($(wc -l < "$tsv") - 1))

# 4. percentiles of |error| per parameter (nearest rank), and |error|/sd at the 95th
pct=$(part percentiles.tsv)
awk -F'\t' '
NR == 1 { for (i = 1; i <= NF; i++) { col[$i] = i; if ($i ~ /^err_/) names[++np] = $i }; next }
{ for (p = 1; p <= np; p++) { e = $(col[names[p]]); if (e == "") continue
      k = ++n[p]; a[p, k] = e < 0 ? -e : e
      sd = $(col["sd_" substr(names[p], 5)])
      if (sd != "" && sd != "inf" && sd > 0) { zn[p]++; z[p, zn[p]] = a[p, k] / sd } } }
function sortp(p, arr, m,   i, j, t) { for (i = 2; i <= m; i++) { t = arr[p, i]
      for (j = i - 1; j >= 1 && arr[p, j] > t; j--) arr[p, j + 1] = arr[p, j]; arr[p, j + 1] = t } }
function pct(p, arr, m, q,   k) { k = int(q * m + 0.999999); if (k < 1) k = 1; if (k > m) k = m; return arr[p, k] }
END {
    printf "parameter\tunit\teyes\tp50\tp90\tp95\tp99\tmax\tz_p95\n"
    unit["err_Q"] = ""; unit["err_Km"] = "D"; unit["err_cyl"] = "D"; unit["err_axis"] = "deg"
    unit["err_tilt_x"] = "deg"; unit["err_tilt_y"] = "deg"
    for (p = 1; p <= np; p++) {
        m = n[p]; if (!m) continue
        sortp(p, a, m); if (zn[p]) sortp(p, z, zn[p])
        u = names[p] in unit ? unit[names[p]] : "um"
        printf "%s\t%s\t%d\t%.4g\t%.4g\t%.4g\t%.4g\t%.4g\t%s\n", substr(names[p], 5), u, m,
               pct(p, a, m, .5), pct(p, a, m, .9), pct(p, a, m, .95), pct(p, a, m, .99),
               a[p, m], zn[p] ? sprintf("%.3g", pct(p, z, zn[p], .95)) : "-"
    }
}' "$tsv" > "$pct"

cpu=$(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo 2>/dev/null | head -1)
awk -v t0="$t0" -v t1="$t1" -v cpu="${cpu:-unknown}" -v n="$(nproc 2>/dev/null || echo ?)" \
    'NR > 1 { s += $4; k++ } END { printf "# wall %.2f s for %d eyes, %.3f s per eye and job (joblog); here: %s, %s cores\n", t1 - t0, k, k ? s / k : 0, cpu, n }' joblog.txt
echo "# $neyes eyes reported, $failed failed (joblog: $DIR/joblog.txt); |error| percentiles;"
echo "# z_p95: the 95th percentile of |error| / reported sd (1.96 when the sd is honest)"
column -t -s "$(printf '\t')" "$pct" 2>/dev/null || cat "$pct"
# (the tables are read from their temporaries, then put in place: a FIFO there is
# only written)
put "$tsv" study.tsv
put "$pct" percentiles.tsv
if [ -x "$PLOT" ]; then
    "$PLOT" study.tsv study.png && echo "# plot: $DIR/study.png"
else
    echo "# no plot: $PLOT not built (make build/obj/cornea_tools/study_plot)"
fi
[ "$failed" -eq 0 ]
