# t_72_imaging.sh -- the imaging engine's frames and centroids (src/imaging/im_frame*,
# im_synth, im_source, im_centroid, im_fit; tests/imaging/t_*.c) in the normal and the
# sanitizer builds of lensmat-imaging.so, its one exported symbol, and a short fuzz of
# the frame readers from the seed corpus tests/imaging/fuzz-corpus.
for b in t_frames t_centroid; do
    for kind in obj asan; do
        lib=$TOP/build/lib; [ "$kind" = asan ] && lib=$TOP/build/asan/lib
        bin=$TOP/build/$kind/imaging_tests/$b
        if [ ! -x "$bin" ]; then fail "$bin (not built)"; continue; fi
        d=$(mktemp -d "$WORK/im.XXXXXX")
        (cd "$TOP" && IM_LIBDIR=$lib LSAN_OPTIONS="suppressions=$TOP/tests/imaging/lsan.supp:fast_unwind_on_malloc=0:print_suppressions=0" "$bin" "$d") > "$WORK/unit.out" 2>&1; rc=$?
        p=$(grep -c '^PASS' "$WORK/unit.out"); f=$(grep -c '^FAIL' "$WORK/unit.out")
        PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
        grep '^FAIL' "$WORK/unit.out" | sed "s|^|$kind/$b: |"
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
            fail "$kind/$b exited $rc"; tail -20 "$WORK/unit.out"; fi
    done
done
check "lensmat-imaging.so exports imaging_get_api only" sh -c \
    "nm -D --defined-only '$TOP/build/lib/lensmat-imaging.so' | grep ' T ' | grep -v ' T _init\$\| T _fini\$' | awk '{print \$3}' | grep -qx imaging_get_api && \
     test \$(nm -D --defined-only '$TOP/build/lib/lensmat-imaging.so' | grep -c ' T ') -le 3"
check "lensmat-imaging.so does not link videoio (that is lensmat-camera.so)" sh -c \
    "! ldd '$TOP/build/lib/lensmat-imaging.so' | grep -q videoio && ldd '$TOP/build/lib/lensmat-camera.so' | grep -q videoio"
fuzz_frames() {
    d=$(mktemp -d "$WORK/fz.XXXXXX")
    "$TOP/build/fuzz_frame" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 \
        -rss_limit_mb=4096 -artifact_prefix="$d/" "$d" "$TOP/tests/imaging/fuzz-corpus" \
        > "$WORK/fuzz_frame.log" 2>&1 || { grep -v 'libpng' "$WORK/fuzz_frame.log" | tail -30; return 1; }
}
if [ -x "$TOP/build/fuzz_frame" ]; then
    check "fuzz: frame readers (short run)" fuzz_frames
else
    fail "fuzz_frame not built"
fi
