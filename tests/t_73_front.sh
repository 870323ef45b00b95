# t_73_front.sh -- the imaging front end of a topographer (issue 19 item 7):
# tests/imaging/t_front.c in the normal and the sanitizer builds (frames from an
# independent forward model: the saturation level of data narrower than the file,
# detection by the spot's integrated SNR against the matched filter's closed form,
# the camera gain from photon transfer with the background clipped at zero), and
# through ./lensmat --spot, frames that program wrote: a 12-bit camera's frame in a
# 16-bit PNG reported saturated, a spot whose peak is 2.2 sigma found at threshold 5
# with the SNR the threshold is on, and "no spot" quoting an SNR below it.
FR=$WORK/front
mkdir -p "$FR"
for kind in obj asan; do
    lib=$TOP/build/lib; [ "$kind" = asan ] && lib=$TOP/build/asan/lib
    bin=$TOP/build/$kind/imaging_tests/t_front
    if [ ! -x "$bin" ]; then fail "$bin (not built)"; continue; fi
    d=$FR/$kind
    mkdir -p "$d"
    (cd "$TOP" && IM_LIBDIR=$lib LSAN_OPTIONS="suppressions=$TOP/tests/imaging/lsan.supp:fast_unwind_on_malloc=0:print_suppressions=0" "$bin" "$d") > "$FR/$kind.out" 2>&1; rc=$?
    p=$(grep -c '^PASS' "$FR/$kind.out"); f=$(grep -c '^FAIL' "$FR/$kind.out")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$FR/$kind.out" | sed "s|^|$kind/t_front: |"
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        fail "$kind/t_front exited $rc"; tail -20 "$FR/$kind.out"; fi
done
front_spot() {   # front_spot NAME FILE: lensmat --spot on FILE at threshold 5, in $FR/NAME
    mkdir -p "$FR/$1" && printf 'file\n%s\n5\nn\n' "$2" > "$FR/$1/in" &&
        (cd "$FR/$1" && "$BIN" --spot -i in r.rec > out 2> err)
}
front_saturated() {
    front_spot sat "$FR/obj/sat12.png" || { cat "$FR/sat/err"; return 1; }
    grep -q '^Frame: 128 x 96 pixels, 16 bits' "$FR/sat/r.rec" &&
        grep -q '^   saturated: [0-9]* pixels left out' "$FR/sat/r.rec" ||
        { cat "$FR/sat/r.rec"; return 1; }
}
check "--spot: a 12-bit camera's frame in a 16-bit PNG: its spot reported saturated" front_saturated
front_faint() {
    front_spot faint "$FR/obj/faint.png" || { cat "$FR/faint/err"; return 1; }
    grep '^Spot 1: ' "$FR/faint/r.rec" | awk '{
        for (i = 1; i <= NF; i++) { if ($i == "x") x = $(i + 2); if ($i == "SNR") s = $(i + 1) }
        ok = x > 69 && x < 71 && s > 5 && s < 8
        if (!ok) print "x " x " SNR " s; exit !ok }'
}
check "--spot: a spot of peak 2.2 sigma found at threshold 5, its SNR (the filter's) above 5" front_faint
front_none() {   # a frame with no spot: "no spot above 5", its best SNR at most 5
    mkdir -p "$FR/none" && printf 'synth\n200\n100\n16\n50\n50\n3\n20\n100\n50\n3\nn\n5\nn\n' > "$FR/none/in" &&
        (cd "$FR/none" && "$BIN" --spot -i in r.rec > out 2> err) || { cat "$FR/none/err"; return 1; }
    grep '^No spot above 5 sigma' "$FR/none/r.rec" | awk '{ s = $NF + 0; ok = s > 2 && s <= 5
        if (!ok) print; exit !ok }'
}
check "--spot: no spot: the best candidate's SNR quoted is at most the threshold" front_none
