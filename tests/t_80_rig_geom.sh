# t_80_rig_geom.sh -- the rig engine's geometry (src/rig/rg_cornea.c ... rg_verify.c)
# through its table (rig.h), checked against independent formulas and against the
# trace engine; normal and sanitizer builds of both modules.
for b in t_geom; do
    unit "$TOP/build/obj/rig_tests/$b"
    unit "$TOP/build/asan/rig_tests/$b"
done
check "lensmat-rig.so exports rig_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-rig.so' | grep ' T ' | awk '{print \$3}')\" = rig_get_api"
# a short libFuzzer run of the geometry keys and the solver (the long run: make fuzz)
fuzz_geom() {
    mkdir -p "$WORK/fuzz-geom"
    "$TOP/build/fuzz_rig_geom" -max_total_time="${FUZZ_SHORT_SECONDS_RIG:-8}" -timeout=5 \
        -artifact_prefix="$WORK/" "$WORK/fuzz-geom" "$TOP/tests/fuzz-rig-geom" \
        > "$WORK/fuzz-geom.log" 2>&1 || { tail -30 "$WORK/fuzz-geom.log"; return 1; }
}
if [ -x "$TOP/build/fuzz_rig_geom" ]; then
    check "fuzz: rig geometry keys and solver (short run)" fuzz_geom
else
    fail "rig geometry fuzz target not built"
fi
