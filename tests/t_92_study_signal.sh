# t_92_study_signal.sh -- a signal to scripts/cornea-study.sh stops its GNU parallel
# and every lensmat job it started (issue 18: `kill PID` ended the script in 4 ms and
# left parallel and its jobs running), says so, exits 128+N and leaves no partial
# table.  Waits are by condition (a job seen, all jobs gone), never by the clock,
# with generous caps for a loaded machine.
study_signal() {
    sig=$1 want=$2
    d=$WORK/ss-$sig; rm -rf "$d"; mkdir -p "$d"
    lm=$d/lm-$sig-$$; ln -s "$BIN" "$lm"   # a unique path: pgrep finds this run's jobs only
    # started as from a terminal's foreground: a background job of this sh would have
    # SIGINT ignored, which no script can trap
    LENSMAT=$lm python3 -c 'import os, signal, sys
signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])' \
        "$TOP/scripts/cornea-study.sh" -M 8 -p 3000 -s 3 -j 2 -o "$d/out" > "$d/log" 2>&1 &
    sp=$!
    i=0; while ! pgrep -f "$lm" > /dev/null; do
        i=$((i + 1)); [ $i -gt 1200 ] && { echo "no job started"; kill $sp; return 1; }
        sleep 0.1; done
    kill -"$sig" $sp
    wait $sp; rc=$?
    [ "$rc" -eq "$want" ] || { echo "exit $rc, want $want"; cat "$d/log"; return 1; }
    i=0; while pgrep -f "$lm" > /dev/null; do
        i=$((i + 1)); [ $i -gt 300 ] && { echo "jobs still running:"; pgrep -fa "$lm"; pkill -KILL -f "$lm"; return 1; }
        sleep 0.1; done
    pgrep -f "parallel.*$lm" > /dev/null && { echo "parallel still running"; return 1; }
    grep -q "interrupted (SIG$sig)" "$d/log" || { echo "no message:"; cat "$d/log"; return 1; }
    ls "$d/out" | grep -q '\.part$' && { echo "partial files left:"; ls "$d/out"; return 1; }
    [ ! -e "$d/out/study.tsv" ]
}
if command -v parallel > /dev/null 2>&1 && [ -x "$BIN" ]; then
    check "cornea-study.sh: SIGTERM stops parallel and its lensmat jobs, exit 143, no partial table" study_signal TERM 143
    check "cornea-study.sh: SIGINT stops parallel and its lensmat jobs, exit 130" study_signal INT 130
else
    echo "t_92_study_signal: GNU parallel not installed, skipped"
fi
