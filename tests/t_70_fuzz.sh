# t_70_fuzz.sh -- a short libFuzzer run of the answer reader, the number parser and
# every dialogue (the first byte chooses it, see tests/fuzz_answers.c), from the seed
# corpus tests/fuzz-corpus (the long run is `make fuzz`).  The seed is fixed
# (FUZZ_SEED, default 1) so a check run is repeatable; `make fuzz` is not.
fuzz_short() {
    mkdir -p "$WORK/fuzz"
    "$TOP/build/fuzz_answers" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 -seed="${FUZZ_SEED:-1}" \
        -print_final_stats=1 -artifact_prefix="$WORK/" "$WORK/fuzz" "$TOP/tests/fuzz-corpus" > "$WORK/fuzz.log" 2>&1 ||
        { grep -A25 'printed nan or inf\|ended with\|ERROR:' "$WORK/fuzz.log" | head -60
          mkdir -p "$TOP/build/fuzz-crashes" && cp "$WORK"/crash-* "$TOP/build/fuzz-crashes/" 2>/dev/null
          echo "(the input is kept in build/fuzz-crashes/)"; return 1; }
}
if [ -x "$TOP/build/fuzz_answers" ]; then
    check "fuzz: answer reader, number parser, every dialogue (short run)" fuzz_short
else
    fail "fuzz target not built"
fi
# The lens model's readers (tests/fuzz_lens.c: thickness prescriptions and .zmx,
# each read back after writing), from the seeds in tests/fuzz-lens.
fuzz_lens_short() {
    mkdir -p "$WORK/fuzz-lens"
    "$TOP/build/fuzz_lens" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 -seed="${FUZZ_SEED:-1}" \
        -print_final_stats=1 -artifact_prefix="$WORK/lens-" "$WORK/fuzz-lens" "$TOP/tests/fuzz-lens" \
        > "$WORK/fuzz-lens.log" 2>&1 ||
        { grep -A25 'does not read\|reads back\|ERROR:' "$WORK/fuzz-lens.log" | head -60
          mkdir -p "$TOP/build/fuzz-crashes" && cp "$WORK"/lens-crash-* "$TOP/build/fuzz-crashes/" 2>/dev/null
          echo "(the input is kept in build/fuzz-crashes/)"; return 1; }
}
if [ -x "$TOP/build/fuzz_lens" ]; then
    check "fuzz: lens readers, thickness prescriptions and .zmx (short run)" fuzz_lens_short
else
    fail "fuzz_lens not built"
fi
