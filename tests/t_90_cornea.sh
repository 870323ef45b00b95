# t_90_cornea.sh -- the cornea analysis engine (src/cornea/): the fit against synthetic
# truth from the rig geometry's forward model (t_fit), the stiff and degenerate scans
# (t_stiff), the final parameters traced through the trace engine (t_trace), the asphere,
# 3 mm-zone Sim K, cone, maps and report (t_models); normal
# and sanitizer builds.
for b in t_fit t_stiff t_trace t_models; do
    unit "$TOP/build/obj/cornea_tests/$b"
    unit "$TOP/build/asan/cornea_tests/$b"
done
check "lensmat-cornea.so exports cornea_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-cornea.so' | grep ' T ' | awk '{print \$3}')\" = cornea_get_api"
# the --cornea-scan dialogue: a simulated scan of the issue-12 eye fitted and reported,
# replayed exactly from its grep'd record, a bad answer refused in a replay
cs_run() {
    printf 'biconic\n-\nspiral\n%s\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n1\n0\n-\n' "$2" \
        > "$WORK/cs.in"
    (cd "$WORK" && "$1" --cornea-scan cs.rec < cs.in > cs.out 2> cs.err)
}
for bin in "$TOP/lensmat" "$TOP/build/asan/lensmat"; do
    [ -x "$bin" ] || { fail "$bin not built"; continue; }
    if cs_run "$bin" 300 && grep -q '^Sim K (n 1.3375): K1 42.89' "$WORK/cs.out" &&
       grep -q '^mean K 43.2' "$WORK/cs.rec" &&
       awk '/^Errors:/ { r = $3; k = $7; exit !(r < 2 && r > -2 && k < 0.01 && k > -0.01) }' "$WORK/cs.out"; then
        pass "--cornea-scan: 300-point scan fitted, Sim K reported, R and mean K errors small"
    else fail "--cornea-scan run"; cat "$WORK/cs.err"; fi
    grep '^input:' "$WORK/cs.rec" | sed 's/^input: //' > "$WORK/cs.in2"
    cp "$WORK/cs.out" "$WORK/cs.out1"
    if (cd "$WORK" && "$bin" --cornea-scan cs2.rec < cs.in2 > cs.out2 2> cs.err2) &&
       grep -v -e '^Output was written' -e '^Times' "$WORK/cs.out1" > "$WORK/cs.a" &&
       grep -v -e '^Output was written' -e '^Times' "$WORK/cs.out2" > "$WORK/cs.b" &&
       cmp -s "$WORK/cs.a" "$WORK/cs.b" && cmp -s "$WORK/cs.rec" "$WORK/cs2.rec"; then
        pass "--cornea-scan replays bit for bit from its record"
    else fail "--cornea-scan replay differs"; fi
    if cs_run "$bin" 5; then fail "--cornea-scan accepted 5 scan points in a replay"
    elif grep -q 'scan points' "$WORK/cs.err"; then pass "--cornea-scan refuses 5 points: $(head -1 "$WORK/cs.err")"
    else fail "--cornea-scan: no message for 5 points"; cat "$WORK/cs.err"; fi
done
# SIGINT during a 10 000-point fit: the fit polls the stop flag, lensmat exits 130
cs_stop() {
    printf 'biconic\n-\nspiral\n10000\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n1\n0\n-\n' \
        > "$WORK/cs4.in"
    (cd "$WORK" && exec "$TOP/lensmat" --cornea-scan cs4.rec < cs4.in > cs4.out 2> cs4.err) &
    p=$!
    sleep 0.4
    kill -INT "$p"
    wait "$p"
    rc=$?
    [ "$rc" -eq 130 ] || { echo "exit $rc"; cat "$WORK/cs4.err"; return 1; }
    ! grep -q '^Errors:' "$WORK/cs4.out"
}
check "--cornea-scan stops on SIGINT mid-fit (exit 130, no report)" cs_stop
