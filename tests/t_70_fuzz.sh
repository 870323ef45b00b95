# t_70_fuzz.sh -- a short libFuzzer run of the answer reader, the number parser and
# every dialogue (the first byte chooses it, see tests/fuzz_answers.c), from the seed
# corpus tests/fuzz-corpus (the long run is `make fuzz`).
fuzz_short() {
    mkdir -p "$WORK/fuzz"
    "$TOP/build/fuzz_answers" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 \
        -print_final_stats=1 -artifact_prefix="$WORK/" "$WORK/fuzz" "$TOP/tests/fuzz-corpus" > "$WORK/fuzz.log" 2>&1 ||
        { tail -30 "$WORK/fuzz.log"; return 1; }
}
if [ -x "$TOP/build/fuzz_answers" ]; then
    check "fuzz: answer reader, number parser, every dialogue (short run)" fuzz_short
else
    fail "fuzz target not built"
fi
