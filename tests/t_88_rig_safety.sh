# t_88_rig_safety.sh -- the rig's safety functions (doc/rig-safety.md): the engine on
# the simulated chip (tests/rig/t_safety.c, both builds: latched faults at each stage
# of a scan, reset, interlock and limit switches stopping motion, missed deadlines,
# lost steps, heartbeat rules, dose against IEC 60825-1's MPE, emission order, GRBL
# homing); the --rig dialogue stopping on a fault (exit 2, said in the record), a scan
# over the dose limit refused before its first pulse, the dose in the record and the
# session's dose log, rigs without a heartbeat; the watchdog reading the configured
# hold; and the libgpiod backend on the kernel's gpio-sim chip (tests/rig/vm_safety.c
# through ../shared/tools/gpio-vm/run).
RIGEX=$TOP/tests/rig/machine.rig
WD=$TOP/build/obj/rig_vm/rig_watchdog
unit "$TOP/build/obj/rig_tests/t_safety" "$RIGEX"
unit "$TOP/build/asan/rig_tests/t_safety" "$RIGEX"
S=$WORK/rigsafe
mkdir -p "$S"
safe_session() {   # safe_session DIR ANSWERS...: lensmat --rig in DIR, record r.rec
    dir=$1; shift
    mkdir -p "$dir"
    printf '%s\n' "$@" > "$dir/in"
    (cd "$dir" && "$BIN" --rig -i in r.rec > out 2> err)
}
# the interlock opens mid-move (homing ends at 26.02 s): the dialogue says the fault
# and stops, exit 2; the simulator saw no violation; everything off at the end
{ cat "$RIGEX"; echo "sim_interlock_open_ms 26300"; } > "$S/il.rig"
safe_il() {
    safe_session "$S/il" "$S/il.rig" sim il.log home joints 5 0 0 0 0 0 expose 10 quit; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; return 1; }
    grep -q '^FAULT latched (interlock: the interlock opened during motion)' "$S/il/r.rec" &&
        grep -q 'fault latched' "$S/il/err" && ! grep -q 'Exposed' "$S/il/r.rec" &&
        ! grep -q VIOLATION "$S/il/il.log" &&
        tail -1 "$S/il/il.log" | grep -q 'final laser=0 light=0 enable=000000'
}
check "rig safety: the interlock mid-move: fault said, session stops, exit 2" safe_il
safe_il_time() {   # the last STEP edge within 1 ms of the opening, from the log
    awk '/interlock open$/ { t = $1 } /FAULT latched/ { for (i = 1; i <= NF; i++)
         if ($i == "edge") e = $(i+1) + 0 } END { exit !(t > 0 && e - t <= 0.001) }' "$S/il/il.log"
}
check "rig safety: ... the last STEP edge within 1 ms of the opening (simulator log)" safe_il_time
check "rig safety: ... its grep'd record replays exactly" sh -c "cd '$S/il' && mv il.log il1.log && grep input: r.rec > in2 && ! '$BIN' --rig r2.rec < in2 > /dev/null 2>&1 && cmp r.rec r2.rec && cmp il1.log il.log"

# the dose: a 1 mW rig; 40 points of 10 ms exceed the MPE (0.4 s: 1.15 of it): refused
# before the first pulse; 10 points pass, with the margin in the record and a dose log
sed 's/^laser_power_mw 0.1 .*/laser_power_mw 1/' "$RIGEX" > "$S/mw.rig"
safe_dose_over() {
    safe_session "$S/over" "$S/mw.rig" sim o.log home scan 40 1.5 10 quit; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; return 1; }
    grep -q '^Dose: 40 exposures of 10 ms at 1 mW, 632.8 nm, .* 1.15 of the MPE' "$S/over/r.rec" &&
        grep -q '^Refused: the dose would exceed the limit' "$S/over/r.rec" &&
        ! grep -q 'moved\|expose\|laser 1' "$S/over/o.log"
}
check "rig safety: a scan over the dose limit is refused before its first pulse" safe_dose_over
safe_dose_ok() {
    safe_session "$S/ok" "$S/mw.rig" sim k.log home scan 10 0.5 10 quit || { cat "$S/ok/err"; return 1; }
    grep -q '^Dose: 10 exposures of 10 ms at 1 mW.* 0.812 of the MPE, margin 1.23 x' "$S/ok/r.rec" &&
        [ "$(grep -c '^exposure ' "$S/ok/r.rec.dose")" -eq 10 ] &&
        grep -q '^exposure 10: 10 ms, 0.2598[0-9]* J/m^2; session 2.598[0-9]* J/m^2 in 0.1 s' "$S/ok/r.rec.dose" &&
        grep -q '^scan planned: 10 exposures' "$S/ok/r.rec.dose" && ! grep -q VIOLATION "$S/ok/k.log"
}
check "rig safety: a scan within it: the dose and margin in the record, a dose log (10 exposures)" safe_dose_ok
# the hold the dose allows: 1 mW, max_on_ms 200: at most 30.3 ms (E t = 18 t^0.75 at 0.2304 s)
sed 's/^heartbeat_timeout_ms 5 .*/heartbeat_timeout_ms 100/' "$S/mw.rig" > "$S/hold.rig"
safe_hold() {
    safe_session "$S/hold" "$S/hold.rig"; rc=$?
    [ "$rc" -eq 2 ] && grep -q 'hold.rig:11: a controller that dies at the end of a 200 ms exposure .* at most 30.3 ms of hold' "$S/hold/err"
}
check "rig safety: a heartbeat hold the dose does not allow is refused (FILE:LINE)" safe_hold

# no heartbeat line: said when the rig is read; emission refused (simulator = gpiod)
sed '/^heartbeat 26/d' "$RIGEX" > "$S/nohb.rig"
safe_nohb() {
    safe_session "$S/nohb" "$S/nohb.rig" sim n.log home expose 10 quit; rc=$?
    [ "$rc" -eq 2 ] && grep -q '^No heartbeat line: the laser will not emit' "$S/nohb/r.rec" &&
        grep -q "no 'heartbeat' line" "$S/nohb/err" && ! grep -q 'laser 1' "$S/nohb/n.log" &&
        grep -q 'no heartbeat: emission refused' "$S/nohb/n.log"
}
check "rig safety: a rig without a heartbeat line: said, and no emission" safe_nohb

# the watchdog reads the hold the rig file configured (30 ms here), and a pump-less
# rig (eye-safe by its own word) is reported as such: nothing cuts that beam
safe_kill() {   # safe_kill NAME RIGFILE: SIGKILL mid-exposure, the watchdog's report
    k=$S/$1; mkdir -p "$k"
    { echo "$2"; echo sim; echo k.log; echo home
      for i in $(seq 40); do echo expose; echo 200; done; echo quit; } > "$k/in"
    rm -f "$k/k.log.state"
    "$WD" "$k/k.log.state" 20 > "$k/wd.out" 2>&1 & wpid=$!
    (cd "$k" && exec "$BIN" --rig -i in r.rec > out 2> err) & pid=$!
    i=0; while [ ! -e "$k/k.log.part" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i+1)); done
    sleep 1; kill -KILL $pid; wait $pid
    wait $wpid || { cat "$k/wd.out"; return 1; }
    cat "$k/wd.out"
}
sed '/^home [0-9]/d; s/^heartbeat_timeout_ms 5 .*/heartbeat_timeout_ms 30/' "$RIGEX" > "$S/rt.rig"
echo "sim_realtime yes" >> "$S/rt.rig"
sed '/^heartbeat /d; /^heartbeat_timeout_ms/d' "$S/rt.rig" > "$S/rtsafe.rig"
echo "eye_safe_without_heartbeat yes" >> "$S/rtsafe.rig"
if [ -x "$WD" ]; then
    safe_kill hold30 "$S/rt.rig" > "$S/hold30.out" 2>&1
    check "rig safety: the watchdog uses the configured hold: SIGKILL mid-exposure, light off within 30 ms + 2" \
        awk '/seen_light=1 line_after=1 light_after=0/ { split($4, a, "="); split($5, b, "=");
             ok = b[2] == 30 && a[2] <= b[2] + 2 } END { exit !ok }' "$S/hold30.out"
    safe_kill nopump "$S/rtsafe.rig" > "$S/nopump.out" 2>&1
    check "rig safety: ... a rig without a pump: the watchdog says nothing cut the light" \
        grep -q 'seen_light=1 line_after=1 light_after=1 .* pump=0' "$S/nopump.out"
else
    fail "rig safety: $WD not built"
fi

# the libgpiod backend on the gpio-sim chip
gpio_vm 24 tests/rig/vm.rig build/obj/rig_vm/vm_safety vm.rig
