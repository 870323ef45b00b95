# t_87_rig_frames.sh -- the --rig closed loop with camera frames (rig file "camera
# frames"): every scan point's landing point becomes a synthetic frame at the detector
# point, the imaging engine's centroid is the detected spot, and it must land within
# the quantisation bound plus 3 sigma of the centroid; exact replay with the fixed
# seed; a frame that cannot show the spot counts as outside; sessions without frames
# never map OpenCV.
RIGGOLD=$TOP/golden/rig/example.rig
F=$WORK/rigframes
mkdir -p "$F"
{ cat "$RIGGOLD"; echo "camera frames"; } > "$F/cam.rig"
frames_session() {   # frames_session DIR ANSWERS...
    dir=$1; shift
    mkdir -p "$dir"
    printf '%s\n' "$@" > "$dir/in"
    (cd "$dir" && "$BIN" --rig -i in r.rec > out 2> err)
}
frames_scan() {
    frames_session "$F/s" "$F/cam.rig" sim s.log home scan 24 1.8 10 quit ||
        { cat "$F/s/err"; return 1; }
    grep -q '^Camera frames: 128x128 pixels of 20 um' "$F/s/r.rec" || return 1
    [ "$(grep -c '^Frame: spot at pixel .*: within' "$F/s/r.rec")" -eq 24 ] || return 1
    ! grep -q OUTSIDE "$F/s/r.rec" && grep -q '^Scan: 24 points, .* 0 outside' "$F/s/r.rec" &&
        grep -q '^Frames: 24, worst detected miss' "$F/s/r.rec"
}
check "rig frames: a 24-point scan, every detected spot within bound + 3 sigma" frames_scan
# the centroid must agree with the traced landing point to well under a pixel (20 um)
frames_close() {
    awk '/^Frame: spot/ { for (i = 1; i <= NF; i++) if ($i == "point" && $(i-1) == "landing")
            { v = $(i+2); if (v + 0 > 2) bad++ } ; n++ }
         END { exit !(n == 24 && !bad) }' "$F/s/r.rec"
}
check "rig frames: each centroid within 2 um (0.1 px) of the traced landing point" frames_close
check "rig frames: the grep'd record replays byte for byte (record and log)" sh -c \
    "cd '$F/s' && mv s.log s1.log && grep input: r.rec > in2 && '$BIN' --rig r2.rec < in2 > /dev/null && cmp r.rec r2.rec && cmp s1.log s.log"
# another seed gives other noise: the frames are really synthesised and measured
frames_seed() {
    { cat "$F/cam.rig"; echo "camera_seed 7"; } > "$F/seed.rig"
    frames_session "$F/seed" "$F/seed.rig" sim - home scan 24 1.8 10 quit || return 1
    grep -q '^Scan: 24 points, .* 0 outside' "$F/seed/r.rec" &&
        ! cmp -s "$F/s/r.rec" "$F/seed/r.rec" >/dev/null 2>&1 &&
        [ "$(grep '^Frame' "$F/s/r.rec" | md5sum)" != "$(grep '^Frame' "$F/seed/r.rec" | md5sum)" ]
}
check "rig frames: another camera_seed, other frames, still within" frames_seed
# a sensor too small to hold the spot: the check fails, a replay exits 2
frames_small() {
    { cat "$RIGGOLD"; echo "camera frames"; echo "camera_pixels 16"; echo "camera_pitch 0.002"; } > "$F/small.rig"
    frames_session "$F/small" "$F/small.rig" sim - home scan 3 1.8 10 quit; rc=$?
    [ "$rc" -eq 2 ] && grep -q '^Frame: .*: OUTSIDE' "$F/small/r.rec" &&
        grep -q 'Scan: 3 points, .* 3 outside' "$F/small/r.rec"
}
check "rig frames: a sensor that cannot hold the spot is outside, exit 2" frames_small
printf 'camera maybe\n' > "$F/badkey.rig"
check "rig frames: a bad camera key names its line" sh -c \
    "printf '%s\n' '$F/badkey.rig' > '$F/bk.in'; cd '$F' && ! '$BIN' --rig -i bk.in bk.rec > /dev/null 2> bk.err && grep -q \"badkey.rig:1: 'camera' takes 'frames' or 'none'\" bk.err"
# OpenCV only where frames are wanted
frames_maps() {
    (cd "$F/s" && LD_DEBUG=files "$BIN" --rig r5.rec < in2 > /dev/null 2> ld.err) &&
        grep -q 'libopencv_core' "$F/s/ld.err" || return 1
    printf '%s\n' "$RIGGOLD" sim - home scan 24 1.8 10 quit > "$F/noframes.in"
    (cd "$F" && LD_DEBUG=files "$BIN" --rig -i noframes.in nf.rec > /dev/null 2> nf.ld) &&
        grep -q 'lensmat-rig' "$F/nf.ld" && ! grep -q -E 'opencv|lensmat-imaging' "$F/nf.ld" &&
        ! grep -q '^Frame' "$F/nf.rec"
}
check "rig frames: a scan with frames maps OpenCV, one without maps none (LD_DEBUG=files)" frames_maps
# the same scan under ASan and UBSan (core and modules: the imaging engine's frames too)
check "rig frames: ASan build, the same scan replays to the same record" sh -c \
    "cd '$F/s' && LENSMAT_LIBDIR='$TOP/build/asan/lib' '$ASAN' --rig r3.rec < in2 > /dev/null && cmp r.rec r3.rec"
