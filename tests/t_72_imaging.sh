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

# The --spot dialogue: the embedded example, exact replay, a frame written and read back
# (PNG and raw) giving the same spot, bad files refused with FILE:LINE in a replay.
SP=$WORK/spot
mkdir -p "$SP"
spot_session() {   # spot_session NAME ANSWERS...: lensmat --spot in $SP/NAME
    d=$SP/$1; shift
    mkdir -p "$d"
    printf '%s\n' "$@" > "$d/in"
    (cd "$d" && "$BIN" --spot -i in r.rec > out 2> err)
}
spot_example_replays() {
    mkdir -p "$SP/ex" && (cd "$SP/ex" && "$BIN" --spot --example r.rec > out 2>&1) || return 1
    grep -q '^One spot' "$SP/ex/r.rec" || return 1
    grep input: "$SP/ex/r.rec" > "$SP/ex/in"
    (cd "$SP/ex" && "$BIN" --spot -i in r2.rec > /dev/null 2>&1) && cmp "$SP/ex/r.rec" "$SP/ex/r2.rec"
}
check "--spot: the example finds one spot and its record replays byte for byte" spot_example_replays
spot_roundtrip() {
    spot_session w synth 64 48 16 30.3 20.6 2.5 3000 200 20 7 y "$SP/f.png" 5 y \
        synth 64 48 16 30.3 20.6 2.5 3000 200 20 7 y "$SP/f.raw" 5 n || return 1
    spot_session r file "$SP/f.png" 5 y raw 64 48 16 "$SP/f.raw" 5 n || return 1
    a=$(grep '^Spot 1' "$SP/w/r.rec" | head -1)
    [ -n "$a" ] && [ "$(grep -c "^$a" "$SP/r/r.rec")" = 2 ] || { echo "write: $a"; grep '^Spot' "$SP/r/r.rec"; return 1; }
    grep -q 'x = 30\.[2-4]' "$SP/w/r.rec"
}
check "--spot: a synthetic frame written as PNG and raw reads back to the same spot" spot_roundtrip
spot_bad_file() {
    head -c 100 "$SP/f.png" > "$SP/cut.png"
    ! spot_session bad file "$SP/cut.png" 5 n || return 1
    grep -q "in:2:.*cut.png: truncated PNG" "$SP/bad/err" || { cat "$SP/bad/err"; return 1; }
    ! grep -q cut.png "$SP/bad/r.rec" || return 1
    ! spot_session badraw raw 640 480 16 "$SP/f.raw" 5 n || return 1
    grep -q "in:5:.*f.raw: a raw 640x480 16-bit frame is 614400 bytes" "$SP/badraw/err" ||
        { cat "$SP/badraw/err"; return 1; }
    ! spot_session badw synth 64 48 16 30 20 2.5 3000 200 20 7 y "$SP/no/dir/x.png" 5 n || return 1
    grep -q "x.png: cannot write" "$SP/badw/err" && [ ! -e "$SP/no" ] || return 1
    ! spot_session badn synth 0 48 || return 1
    grep -q 'in:2:' "$SP/badn/err"
}
check "--spot: truncated PNG, short raw and unwritable output refused with FILE:LINE" spot_bad_file
spot_none_several() {
    spot_session none synth 200 100 16 50 50 3 40 100 50 3 n 5 n || return 1
    grep -q '^No spot above 5 sigma; the best candidate' "$SP/none/r.rec" || return 1
    spot_session sat synth 200 100 8 50.4 50.7 3 1000 10 3 3 n 5 n || return 1
    grep -q 'saturated:' "$SP/sat/r.rec" && grep -q 'x = 50\.[345]' "$SP/sat/r.rec" || { cat "$SP/sat/r.rec"; return 1; }
    spot_session edge synth 200 100 16 0.5 50 3 1000 100 20 3 n 5 n || return 1
    grep -q 'cut by the frame edge' "$SP/edge/r.rec"
}
check "--spot: no spot (best SNR said), saturated and edge spots reported" spot_none_several
check "--spot is listed by --help" sh -c "'$BIN' --help | grep -q -- '--spot'"
spot_asan() {
    mkdir -p "$SP/asan" && cd "$SP/asan" &&
        LSAN_OPTIONS="suppressions=$TOP/tests/imaging/lsan.supp:print_suppressions=0" \
        "$ASAN" --spot --example r.rec > out 2>&1; rc=$?; cd "$TOP"
    [ $rc -eq 0 ] && cmp "$SP/asan/r.rec" "$SP/ex/r.rec"
}
check "--spot under ASan/UBSan (lensmat and the imaging module): the same record" spot_asan
spot_stream() {
    for i in 1 2 3; do
        spot_session s$i synth 64 48 16 2$i.5 20 2.5 2000 100 20 $i y "$SP/seq$(printf %04d $i).png" 5 n || return 1
    done
    spot_session st stream "$SP/seq%04d.png" 1 10 5 n || return 1
    grep -q '^Frame 3 (64x48, t = 3.000): x = 23\.[45]' "$SP/st/r.rec" && grep -q '^3 frames read $' "$SP/st/r.rec" ||
        { cat "$SP/st/r.rec"; return 1; }
    grep input: "$SP/st/r.rec" > "$SP/st/in2"
    (cd "$SP/st" && "$BIN" --spot -i in2 r2.rec > /dev/null) && cmp "$SP/st/r.rec" "$SP/st/r2.rec" || return 1
    spot_session st2 stream "$SP/seq%04d.png" 2 1 5 n && grep -q '^1 frames read, the source has more' "$SP/st2/r.rec" || return 1
    ! spot_session st3 stream "$SP/seq%04d.png" 7 2 5 n && grep -q 'in:3:.*no frame number 7' "$SP/st3/err" || return 1
    ! spot_session st4 stream cam:57 2 5 n && grep -q 'in:2:.*cam:57: no such camera' "$SP/st4/err" || return 1
    "$TOP/build/obj/imaging_tests/bench_load" "$TOP/build/lib" --make-avi "$SP/v.avi" || return 1
    spot_session st5 stream "$SP/v.avi" 3 5 n && grep -q '^Frame 3 (640x480' "$SP/st5/r.rec" &&
        grep -q '^3 frames read, the source has more' "$SP/st5/r.rec"
}
check "--spot stream: a numbered sequence, a video (through lensmat-camera.so), an absent camera" spot_stream
