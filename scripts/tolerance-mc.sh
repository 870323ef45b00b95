#!/bin/sh
# tolerance-mc.sh -- a Monte Carlo of many built lenses (lensmat --tolerance, mc) cut
# into independent jobs of C lenses each, run under GNU parallel over this machine's
# cores or several machines (--sshlogin, as scripts/cornea-study.sh does for eyes);
# every job is one `lensmat --tolerance` run from its own answers (so it replays from
# its record) and writes its rows; the rows are joined in lens order into DIR/table.txt
# and summarised by `lensmat --tolerance` (table) into DIR/summary.rec.  Lens k draws
# from its own stream of (seed, k), so the table is byte-identical to one process's.
#
#     scripts/tolerance-mc.sh -f LENS [-t TOLFILE] [-N LENSES] [-C CHUNK] [-s SEED]
#                             [-d uniform|gauss] [-c bfd|none] [-l LIMIT_UM] [-j JOBS]
#                             [-o DIR] [-S SSHLOGIN]
#
# Defaults: -t - (the lens file's own tol lines), -N 10000, -C 500, -s 1, -d uniform,
# -c bfd, -l 0 (no yield), -j 0 (every core), -o tolerance-mc.  LENSMAT names the
# lensmat to run (default this tree's ./lensmat).  With -S the lens and tolerance
# files must be at the same path on every host.
set -e
TOP=$(cd "$(dirname "$0")/.." && pwd)
LENSMAT=${LENSMAT:-$TOP/lensmat}
LENS="" TOL=- N=10000 C=500 SEED=1 DIST=uniform COMP=bfd LIMIT=0 JOBS=0 DIR=tolerance-mc SSH=""
while getopts "f:t:N:C:s:d:c:l:j:o:S:h" o; do
    case $o in
    f) LENS=$OPTARG ;; t) TOL=$OPTARG ;; N) N=$OPTARG ;; C) C=$OPTARG ;; s) SEED=$OPTARG ;;
    d) DIST=$OPTARG ;; c) COMP=$OPTARG ;; l) LIMIT=$OPTARG ;; j) JOBS=$OPTARG ;;
    o) DIR=$OPTARG ;; S) SSH=$OPTARG ;;
    *) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
    esac
done
[ -n "$LENS" ] || { echo "$0: -f LENS is needed" >&2; exit 2; }
case $N$C$SEED$JOBS in ''|*[!0-9]*) echo "$0: -N, -C, -s and -j want whole numbers" >&2; exit 2 ;; esac
[ "$N" -ge 1 ] && [ "$C" -ge 1 ] || { echo "$0: -N and -C must be at least 1" >&2; exit 2; }
command -v parallel >/dev/null 2>&1 && parallel --version 2>/dev/null | grep -q 'GNU parallel' ||
    { echo "$0: GNU parallel is not installed (scripts/install-deps.sh installs it)" >&2; exit 3; }
[ -x "$LENSMAT" ] || { echo "$0: $LENSMAT not built (run make)" >&2; exit 3; }
case $LENS in /*) ;; *) LENS=$(pwd)/$LENS ;; esac
case $TOL in -|/*) ;; *) TOL=$(pwd)/$TOL ;; esac
mkdir -p "$DIR"
cd "$DIR"
rm -f part-*.in part-*.rec part-*.tab part-*.out table.txt summary.rec

# 1. one answers file per job: lenses first .. first + count - 1
k=1 j=0
while [ "$k" -le "$N" ]; do
    j=$((j + 1))
    n=$C
    [ $((k + n - 1)) -le "$N" ] || n=$((N - k + 1))
    f=$(printf 'part-%06d' "$j")
    printf '%s\n%s\nmc\n%d\n%d\n%s\n%s\n%s\n%s\n%s.tab\n' "$LENS" "$TOL" "$n" "$k" "$SEED" \
        "$DIST" "$COMP" "$LIMIT" "$f" > "$f.in"
    k=$((k + n))
done

# 2. the jobs, under GNU parallel (no home-made scheduler)
set -- --jobs 100% --halt now,fail=1 --joblog joblog.txt
[ "$JOBS" = 0 ] || set -- --jobs "$JOBS" --halt now,fail=1 --joblog joblog.txt
[ -z "$SSH" ] || set -- "$@" --sshlogin "$SSH" --trc '{.}.tab' --trc '{.}.rec'
ls part-*.in | parallel "$@" "'$LENSMAT' --tolerance {.}.rec < {} > {.}.out 2>&1"

# 3. the rows in lens order (part names sort as numbers), then one summary
for f in part-*.tab; do cat "$f"; done > table.txt.part && mv table.txt.part table.txt
printf '%s\n%s\ntable\ntable.txt\n%s\n' "$LENS" "$TOL" "$LIMIT" | "$LENSMAT" --tolerance summary.rec > /dev/null
grep -E '^  (.* lenses \(|RMS um|efl mean|boresight|yield)' summary.rec
echo "  $N lenses, $j jobs: $DIR/table.txt, $DIR/summary.rec"
