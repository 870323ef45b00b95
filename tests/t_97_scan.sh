# t_97_scan.sh -- the scan on the machine (issue 19 item 6, doc/scan-time.md):
# --cornea-scan on the simulated chip with golden/rig/example.rig visits the points in
# the planned order, on the fly (pulses between STEP edges) or stop and go, its
# machine time is the simulator's clock, every safety check holds (interlock, dose
# before the first pulse, heartbeat, no step with the laser on where the rig does not
# allow it); and the fixation drift test (tests/topo/t_drift.c, both builds).
SC=$WORK/scan97
mkdir -p "$SC"
RIGEX=$TOP/golden/rig/example.rig
sc_in() {       # sc_in FILE RIG LOG PATTERN N SOURCE MS: the biconic eye of the bench
    if [ "$6" = frames ]; then src='frames\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-'
    else src='model\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n14'; fi
    printf "biconic\n%s\nsim\n%s\n%s\n%s\n%s\n12\n$src\n1\n0\n-\n" "$2" "$3" "$7" "$4" "$5" > "$1"
}
sc_run() { (cd "$SC" && "$BIN" --cornea-scan -i "$1" "$2" > "$2.out" 2> "$2.err"); }
# 1. on the fly: every point pulsed once, 0.02 ms each, the light never on with the
#    simulator's VIOLATION checks failing, the machine's time what its clock says
sc_fly() {
    sc_in "$SC/f.in" "$RIGEX" f.log rings 300 frames 0.02
    sc_run f.in f.rec || { cat "$SC/f.rec.err"; return 1; }
    grep -q '^Scan on the machine: 300 exposures on the fly, in .* order: [0-9.]* s of machine time' "$SC/f.rec" &&
    [ "$(grep -c ' laser 1$' "$SC/f.log")" -eq 300 ] && [ "$(grep -c ' laser 0' "$SC/f.log")" -eq 300 ] &&
    ! grep -q VIOLATION "$SC/f.log" &&
    grep -q 'final laser=0 light=0 enable=000000 .* violations=0' "$SC/f.log" &&
    # each pulse 20 us on the simulator's clock (laser 1 to laser 0), never longer
    awk '/ laser 1$/ { on = $1 } / laser 0/ { d = $1 - on; if (d > m) m = d; if (d < 1.9e-5) bad = 1 }
         END { exit !(m < 2.1e-5 && !bad) }' "$SC/f.log" &&
    # the machine time: the log's first move to its last pulse's end within a few
    # control steps and the final settle (2 ms) of the reported figure
    t=$(sed -n 's/^Scan on the machine: .* order: \([0-9.]*\) s of machine time.*/\1/p' "$SC/f.rec") &&
    awk -v t="$t" '/^[0-9.]* homed:/ { h = $1 } / laser 0/ { e = $1 }
                   END { d = e - h; exit !(d > 0 && t - d > 0 && t - d < 0.01) }' "$SC/f.log" &&
    grep -q '^Spots: 300 fitted, 0 rejected' "$SC/f.rec" &&
    awk '/^Errors:/ { r = $3; k = $7; exit !(r < 8 && r > -8 && k < 0.05 && k > -0.05) }' "$SC/f.rec" &&
    grep -q '^Fixation: the eye.s pose in [0-9]* time segments agrees with one pose' "$SC/f.rec" &&
    grep -q '^Dose: 300 exposures of 0.02 ms' "$SC/f.rec"
}
check "scan: 300 points on the fly on the simulated chip (one 20 us pulse each, no VIOLATION, fitted)" sc_fly
# 2. the record replays to the same record (simulated time is deterministic)
sc_replay() {
    grep '^input:' "$SC/f.rec" | sed 's/^input: //; s/^f\.log$/f2.log/' > "$SC/f2.in" &&
        sc_run f2.in f2.rec && [ "$(grep -v '^input' "$SC/f.rec")" = "$(grep -v '^input' "$SC/f2.rec")" ]
}
check "scan: the on-the-fly scan's record replays to the same record" sc_replay
# 3. a rig that does not allow it: stop and go, in the planner's order (shorter than
#    the spiral's own, both predicted), the laser only at rest (the simulator's check)
sc_stopgo() {
    sed 's/^expose_moving yes.*/expose_moving no/' "$RIGEX" > "$SC/sg.rig"
    sc_in "$SC/s.in" "$SC/sg.rig" s.log spiral 100 model 1
    sc_run s.in s.rec || { cat "$SC/s.rec.err"; return 1; }
    line=$(grep '^Scan on the machine: 100 exposures stop and go, in the planner.s order' "$SC/s.rec") &&
    echo "$line" | awk '{ for (i = 1; i <= NF; i++) if ($i == "(predicted") p = $(i + 1) + 0;
                               else if ($i == "order" && $(i - 1) == "own") o = $(i + 1) + 0 }
                         END { exit !(p > 0 && o > 2 * p) }' &&
    [ "$(grep -c ' laser 1$' "$SC/s.log")" -eq 100 ] && ! grep -q VIOLATION "$SC/s.log"
}
check "scan: stop and go where the rig does not allow pulses on the fly (planned order, laser at rest)" sc_stopgo
# 4. the dose of the whole sweep is checked before its first pulse: a laser 30 times
#    stronger (single exposures shortened to 1 ms and the pump's hold to 0.1 ms, so the
#    rig file itself is accepted) is refused, 1.21 times the MPE, and the log shows no
#    light at all
sc_dose() {
    sed 's/^laser_power_mw .*/laser_power_mw 3/; s/^max_on_ms .*/max_on_ms 1/; s/^heartbeat_timeout_ms .*/heartbeat_timeout_ms 0.1/' \
        "$RIGEX" > "$SC/d.rig"
    sc_in "$SC/d.in" "$SC/d.rig" d.log rings 300 model 0.02
    ! sc_run d.in d.rec && grep -q 'refused before its first pulse' "$SC/d.rec" &&
        ! grep -q ' laser 1' "$SC/d.log" && ! grep -q ' light 1' "$SC/d.log"
}
check "scan: the sweep's whole dose refused before the first pulse (no light in the log)" sc_dose
# 5. the interlock opening mid-sweep: the laser off and the drivers off within a
#    control step (40 us), the fault latched, the scan fails
sc_interlock() {
    # the sweep starts after homing (about 4.4 s): open it 0.4 s into the sweep
    sed 's/^interlock 25 active_low.*/interlock 25 active_low\nsim_interlock_open_ms 4800/' "$RIGEX" > "$SC/i.rig"
    sc_in "$SC/i.in" "$SC/i.rig" i.log rings 300 model 0.02
    ! sc_run i.in i.rec && grep -q 'interlock' "$SC/i.rec.err" &&
    grep -q 'FAULT latched (interlock)' "$SC/i.log" && ! grep -q VIOLATION "$SC/i.log" &&
    awk '/interlock open/ && !o { o = $1 } / enable m1a=0/ && o && !e { e = $1 }
         END { exit !(o > 4.4 && e >= o && e - o <= 4.1e-5) }' "$SC/i.log"
}
check "scan: the interlock opening mid-sweep stops it within a control step (fault latched)" sc_interlock
# 6. fixation drift (10 and 50 um, slow and saccadic): flagged, measured to 30 %, and
#    not flagged without drift (a toric eye, a sphere, a cone)
sc_unit() {     # unit with arguments: BIN ARGS...
    if [ ! -x "$1" ]; then fail "$1 (not built)"; return; fi
    (cd "$TOP" && "$@") > "$WORK/unit.out" 2>&1; rc=$?
    p=$(grep -c '^PASS' "$WORK/unit.out"); f=$(grep -c '^FAIL' "$WORK/unit.out")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$WORK/unit.out" | sed "s|^|$(basename "$1"): |"
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then fail "$1 exited $rc"; tail -20 "$WORK/unit.out"; fi
}
sc_unit "$TOP/build/obj/topo_tests/t_drift" 600
sc_unit "$TOP/build/asan/topo_tests/t_drift" 200
