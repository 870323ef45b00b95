# t_86_rig_dialogue.sh -- the --rig dialogue on the simulated chip: the example, exact
# replay of a grep'd record (same record, same simulator log), bad input (rig files,
# travel, interlock open at start, a home switch that never trips, exposing before
# homing), and the laser off first on every way out: SIGINT, SIGTERM and SIGHUP
# mid-exposure and while waiting for an answer, end of input, and SIGKILL with the
# heartbeat watchdog (tests/rig/rig_watchdog.c) outside the killed process.
RIGEX=$TOP/tests/rig/machine.rig
RIGGOLD=$TOP/golden/rig/example.rig
WD=$TOP/build/obj/rig_vm/rig_watchdog
# rig_session DIR ANSWERS...: lensmat --rig in DIR, answers in DIR/in, record r.rec
rig_session() {
    dir=$1; shift
    mkdir -p "$dir"
    printf '%s\n' "$@" > "$dir/in"
    (cd "$dir" && "$BIN" --rig -i in r.rec > out 2> err)
}
D=$WORK/rig
mkdir -p "$D"
# a paced rig (sim_realtime) without home switches, for the signal tests
# (the pump's hold is 50 ms here, not 5: a loaded test machine may not run the
# paced simulator every 5 ms, and the watchdog would see a real pump run down)
sed '/^home [0-9]/d; s/^heartbeat_timeout_ms 5 .*/heartbeat_timeout_ms 50/' "$RIGEX" > "$D/rt.rig"
echo "sim_realtime yes" >> "$D/rt.rig"

check "rig: the embedded example runs" sh -c "cd '$TOP' && '$BIN' --rig --example '$D/ex.rec' > '$D/ex.out' && grep -q 'Exposed 20 ms' '$D/ex.rec'"
rig_replay() {
    rig_session "$D/a" "$RIGEX" sim a.log home joints 1 -2 0.5 -0.25 3 -4 expose 20 \
        joints 0 0 0 0 0 0 expose 5 quit || return 1
    mv "$D/a/a.log" "$D/a/first.log"
    grep input: "$D/a/r.rec" > "$D/a/in2"
    (cd "$D/a" && "$BIN" --rig r2.rec < in2 > out2 2> err2) || return 1
    diff "$D/a/r.rec" "$D/a/r2.rec" && cmp "$D/a/first.log" "$D/a/a.log" &&
        ! grep -q VIOLATION "$D/a/a.log" && [ ! -e "$D/a/a.log.part" ] &&
        tail -1 "$D/a/a.log" | grep -q 'final laser=0 light=0 enable=000000'
}
check "rig: a grep'd record replays exactly (record and simulator log)" rig_replay
check "rig: ASan build, the same session" sh -c "cd '$D/a' && LENSMAT_LIBDIR='$TOP/build/asan/lib' '$ASAN' --rig r3.rec < in2 > /dev/null && diff r.rec r3.rec"

# bad input: clear message, non-zero exit in replay, the record keeps what was accepted
rig_bad() {   # rig_bad NAME WANT ANSWERS...
    rn=$1; want=$2; shift 2
    rig_session "$D/$rn" "$@"; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; return 1; }
    grep -q -- "$want" "$D/$rn/err" || { cat "$D/$rn/err"; return 1; }
}
check "rig: a missing rig file (FILE:LINE)" rig_bad nofile "in:1: the rig file: nothere.rig: No such file" nothere.rig
printf 'chip x\nlaser 1\nlazer 2\n' > "$D/bad.rig"
check "rig: a malformed rig file names its line" rig_bad badfile "bad.rig:3: unknown key 'lazer'" "$D/bad.rig"
check "rig: the record keeps the accepted answers" sh -c "grep -c input: '$D/badfile/r.rec' | grep -qx 0"
check "rig: a move outside travel is refused, laser off" rig_bad travel \
    "in:11: axis u: 25 mm is outside its travel" "$RIGEX" sim t.log home joints 0 0 25 0 0 0
check "rig: ... before any pulse" sh -c "! grep -q '^.* moved' '$D/travel/t.log' && tail -1 '$D/travel/t.log' | grep -q 'final laser=0'"
check "rig: ... and its record holds every answer" sh -c "grep -c input: '$D/travel/r.rec' | grep -qx 11"
sed 's/^settle_ms 5.*/settle_ms 5\nsim_interlock open/' "$RIGEX" > "$D/il.rig"
check "rig: an interlock open at start" rig_bad ilopen "the interlock (line 25) is open" "$D/il.rig" sim -
sed 's/^axis m2a$/axis m2a\nsim_home broken/' "$RIGEX" > "$D/brk.rig"
check "rig: a home switch that never trips times out" rig_bad brk \
    "axis m2a: its home switch (line 22) did not trip within 30 s" "$D/brk.rig" sim - home
check "rig: no exposure before homing" rig_bad nohome "not homed" "$RIGEX" sim - expose 10
check "rig: an exposure longer than max_on_ms" rig_bad longexp "at most the rig's max_on_ms 200" \
    "$RIGEX" sim - home expose 500
check "rig: the log may not overwrite the rig file" rig_bad logrig "is the rig file" "$D/rt.rig" sim "$D/rt.rig"
check "rig: the log may not overwrite the answers" rig_bad login "" "$RIGEX" sim in
check "rig: gpiod with an unknown chip" rig_bad nochip "no GPIO chip 'nochip9'" \
    "$(sed 's/^chip gpiochip0/chip nochip9/' "$RIGEX" > "$D/nc.rig"; echo "$D/nc.rig")" gpiod
rig_eof() {   # the answers end mid-session: an error in a replay, the machine closed
    mkdir -p "$D/eof"
    printf '%s\n' "$D/rt.rig" sim e.log home expose 10 > "$D/eof/in"
    (cd "$D/eof" && "$BIN" --rig -i in r.rec > out 2> err); rc=$?
    [ "$rc" -eq 2 ] && grep -q 'end of input' "$D/eof/err" &&
        tail -1 "$D/eof/e.log" | grep -q 'final laser=0 light=0 enable=000000'
}
check "rig: end of input closes the machine: laser off, drivers disabled" rig_eof

# signals mid-exposure: laser off first, then drivers, exit 128+N
# log_growing LOG: the simulator writes LOG in a unique LOG.part.XXXXXX until it closes
log_growing() { for f in "$1".part.*; do [ -e "$f" ] && return 0; done; return 1; }
rig_signal() {   # rig_signal SIG N
    s=$D/sig$1; mkdir -p "$s"
    { echo "$D/rt.rig"; echo sim; echo s.log; echo home
      for i in $(seq 40); do echo expose; echo 200; done; echo quit; } > "$s/in"
    (cd "$s" && exec "$BIN" --rig -i in r.rec > out 2> err) & pid=$!
    i=0; while ! log_growing "$s/s.log" && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); done
    sleep 1; kill -"$1" $pid; wait $pid; rc=$?
    [ "$rc" -eq $((128 + $2)) ] || { echo "exit $rc"; return 1; }
    [ -e "$s/s.log" ] && [ ! -e "$s/s.log.part" ] || { echo "log not completed"; return 1; }
    grep -q 'laser 1' "$s/s.log" || { echo "never exposed"; return 1; }
    lo=$(grep -n 'laser 0' "$s/s.log" | tail -1 | cut -d: -f1)
    en=$(grep -n 'enable m1a=0' "$s/s.log" | tail -1 | cut -d: -f1)
    [ -n "$lo" ] && [ -n "$en" ] && [ "$lo" -lt "$en" ] || { echo "order: laser $lo enable $en"; return 1; }
    tail -1 "$s/s.log" | grep -q 'final laser=0 light=0 enable=000000' && ! grep -q VIOLATION "$s/s.log"
}
check "rig: SIGINT mid-exposure: laser off, then drivers, exit 130" rig_signal INT 2
check "rig: SIGTERM mid-exposure: the same, exit 143" rig_signal TERM 15
check "rig: SIGHUP mid-exposure: the same, exit 129" rig_signal HUP 1
rig_signal_waiting() {   # a signal while lensmat waits for an answer: the stop hook
    s=$D/sigwait; mkdir -p "$s"; rm -f "$s/fifo"; mkfifo "$s/fifo"
    (cd "$s" && exec "$BIN" --rig -i fifo r.rec > out 2> err) & pid=$!
    exec 7> "$s/fifo"
    printf '%s\n' "$RIGEX" sim w.log home joints 1 >&7
    i=0; while ! grep -q 'Homed' "$s/r.rec" 2>/dev/null && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); done
    sleep 0.2; kill -TERM $pid; wait $pid; rc=$?; exec 7>&-
    [ "$rc" -eq 143 ] || { echo "exit $rc"; return 1; }
    grep -q 'stop: laser 0' "$s/w.log" && grep -A1 'stop: laser 0' "$s/w.log" | grep -q 'stop: enable 0' &&
        tail -1 "$s/w.log" | grep -q 'final (stopped) laser=0 light=0 enable=000000'
}
check "rig: SIGTERM while waiting for an answer: the stop hook, laser first" rig_signal_waiting
rig_sigkill() {
    s=$D/kill; mkdir -p "$s"
    { echo "$D/rt.rig"; echo sim; echo k.log; echo home
      for i in $(seq 40); do echo expose; echo 200; done; echo quit; } > "$s/in"
    rm -f "$s/k.log.state"
    "$WD" "$s/k.log.state" 20 > "$s/wd.out" 2>&1 & wpid=$!
    (cd "$s" && exec "$BIN" --rig -i in r.rec > out 2> err) & pid=$!
    i=0; while ! log_growing "$s/k.log" && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); done
    sleep 1; kill -KILL $pid; wait $pid; rc=$?
    wait $wpid || { echo "watchdog failed:"; cat "$s/wd.out"; return 1; }
    cat "$s/wd.out"
    [ "$rc" -eq 137 ] || { echo "lensmat exit $rc"; return 1; }
    # the line stays on (nothing could switch it off); the pump turns the light off
    grep -q 'seen_light=1 line_after=1 light_after=0' "$s/wd.out" &&
        awk '{ split($4, a, "="); split($5, b, "="); exit !(a[2] <= b[2] + 2) }' "$s/wd.out"
}
if [ -x "$WD" ]; then
    check "rig: SIGKILL mid-exposure: the laser line stays high, the heartbeat pump drops the light within its hold time" rig_sigkill
else
    fail "rig: $WD not built"
fi

# the closed loop (section 5): a scan commanded through the dialogue, each point's
# simulated motors through the exact forward model, within the quantisation bound
rig_scan() {
    rig_session "$D/scan" "$RIGGOLD" sim sc.log home point height 1 30 scan 40 1.8 10 quit ||
        { cat "$D/scan/err"; return 1; }
    grep -q 'Scan: 40 points, .* 0 outside' "$D/scan/r.rec" || return 1
    [ "$(grep -c 'Simulated motors: detector miss .* (traced: .*: within' "$D/scan/r.rec")" -eq 41 ] || return 1
    [ "$(grep -c '^[0-9.]* laser 1' "$D/scan/sc.log")" -eq 40 ] && ! grep -q VIOLATION "$D/scan/sc.log"
}
check "rig: a 40-point scan lands every spot within the quantisation bound (closed loop)" rig_scan
check "rig: ... and its grep'd record replays exactly" sh -c "cd '$D/scan' && mv sc.log sc1.log && grep input: r.rec > in2 && '$BIN' --rig r2.rec < in2 > /dev/null && diff r.rec r2.rec && cmp sc1.log sc.log"
check "rig: a target off the cornea is refused" rig_bad offcornea "in:8: target at height 5 mm is outside the cornea" \
    "$RIGGOLD" sim - home point height 5 0
check "rig: a scan of 2.5 points is refused" rig_bad halfscan "2.5 points: give a whole number" \
    "$RIGGOLD" sim - home scan 2.5

# on a terminal: a bad rig file is explained and asked again; a refused move is said
# and the session goes on; the refused answer is not recorded
rig_tty() {
    python3 - "$BIN" "$D/tty" "$RIGEX" "$TOP/tests" <<'PYEOF'
import os, sys
bin_, d, rig = sys.argv[1:4]
sys.path.insert(0, sys.argv[4])
from ptydrive import drive
os.makedirs(d, exist_ok=True)
with open(os.path.join(d, "broken.rig"), "w") as f: f.write("chip a\nlaser x\n")
rc, out = drive([bin_, "--rig", "t.rec"],
                [b"broken.rig\n", (rig + "\n").encode(), b"sim\n", b"t.log\n", b"home\n",
                 b"joints\n", b"0\n", b"0\n", b"99\n", b"0\n", b"0\n", b"0\n", b"expose\n",
                 b"5\n", b"quit\n"], cwd=d, home=d, timeout=60)
rec = open(os.path.join(d, "t.rec")).read()
fails = []
if rc != 0: fails.append("exit %d" % rc)
if "broken.rig:2: 'x' is not a line offset" not in out: fails.append("no re-ask for the rig file")
if "Refused: axis u: 99 mm is outside its travel" not in out: fails.append("no refusal")
if "Exposed 5 ms" not in rec: fails.append("the session did not go on")
if "broken" in rec: fails.append("a refused answer was recorded")
print("\n".join(fails) or "ok", out[-800:] if fails else "")
sys.exit(1 if fails else 0)
PYEOF
}
if command -v python3 > /dev/null; then
    check "rig tty: a bad rig file is asked again, a refused move does not end the session" rig_tty
fi
cp "$RIGEX" "$D/x.state"
check "rig: the log's shared state file may not overwrite the rig file either" rig_bad logstate \
    "x.state' is the rig file" "$D/x.state" sim "$D/x"
