# t_84_rig_machine.sh -- the rig engine's machine half on the simulated chip
# (tests/rig/t_machine.c: rig file reader, homing, coordinated moves, travel, exposure,
# interlock, heartbeat, emergency path, replayed log), both builds; a short fuzz run
# of the rig-file reader (the long run is `make fuzz-rig`).
unit "$TOP/build/obj/rig_tests/t_machine"
unit "$TOP/build/asan/rig_tests/t_machine"
fuzz_rig_short() {
    mkdir -p "$WORK/fuzz-rig"
    "$TOP/build/fuzz_rig_file" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 \
        -artifact_prefix="$WORK/" "$WORK/fuzz-rig" "$TOP/tests/fuzz-rig" > "$WORK/fuzz-rig.log" 2>&1 ||
        { tail -30 "$WORK/fuzz-rig.log"; return 1; }
}
if [ -x "$TOP/build/fuzz_rig_file" ]; then
    check "fuzz: rig-file reader (short run)" fuzz_rig_short
else
    fail "build/fuzz_rig_file not built"
fi
