# t_91_cornea_loop.sh -- the --cornea-scan measurement loop (issue 12 section 1): the
# rig's plan, each spot traced through the eye, a full synthetic frame from the
# imaging engine and its centroid, the fit, the fitted cornea traced against the fit's
# model; rejected spots listed with their reason; the same record and report for 1
# and 2 threads; the simulated chip in the loop, and SIGTERM mid-scan (laser off, no
# report under its final name); OpenCV mapped only when frames are used.
CL=$WORK/cnloop
mkdir -p "$CL"
RIGGOLD=$TOP/golden/rig/example.rig
cl_frames() {   # cl_frames FILE N PITCH WIDTH HEIGHT REPORT [PATTERN [SAVE]]: seed 1, no
                # cone, a report NAME (NAME.txt, .csv, .json; no maps) or -
    printf 'biconic\n-\n%s\n%s\n12\nframes\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n%s\n%s\n%s\n%s\n1\n0\n%s\n' \
        "${7:-spiral}" "$2" "$3" "$4" "$5" "${8:--}" "$6" > "$1"
    [ "$6" = - ] || echo n >> "$1"
}
cl_run() {      # cl_run BIN IN REC [env...]: in $CL, stdout to REC.out
    bin=$1; in=$2; rec=$3; shift 3
    (cd "$CL" && env "$@" "$bin" --cornea-scan -i "$in" "$rec" > "$rec.out" 2> "$rec.err")
}
# 1. the example: 300 points through frames, fitted, every spot used, tracer agrees
cl_example() {
    (cd "$CL" && "$BIN" --cornea-scan --example ex.rec > ex.out 2> ex.err) || { cat "$CL/ex.err"; return 1; }
    grep -q '^Frames: 640x480 pixels of 14 um' "$CL/ex.rec" &&
    grep -q '^Scanned 300 points, 300 spots on the detector' "$CL/ex.rec" &&
    grep -q '^Spots: 300 fitted, 0 rejected' "$CL/ex.rec" &&
    grep -q '^Tracer check: the fitted cornea traced for 300 poses, .*: agrees' "$CL/ex.rec" &&
    # K1 within 3.5 of its sd (0.013 D) of the true eye's flat meridian, 337.5 / R flat
    awk '/^True eye:/ { kt = 337.5 / $5 } /^Sim K \(n 1.3375\)/ { k = $6 }
         END { exit !(kt > 42 && (k - kt < 0.045 && kt - k < 0.045)) }' "$CL/ex.rec" &&
    # the centroid's own sigma is the imaging benchmark's 0.04 px (14 um pixels)
    awk '/^Scanned/ { s = $(NF-1); exit !(s > 0.5 && s < 0.65) }' "$CL/ex.rec" &&
    # errors within 3 of the fit's own sd (R sd about 2.6 um, mean K about 0.015 D)
    awk '/^Errors:/ { r = $3; k = $7; exit !(r < 8 && r > -8 && k < 0.05 && k > -0.05) }' "$CL/ex.rec" &&
    ! grep -q '^Times' "$CL/ex.rec" && grep -q '^Times (' "$CL/ex.out"
}
check "cornea loop: the example (300 frames) fitted, all spots used, tracer check agrees" cl_example
# 2. the same record and report for 1 and 2 threads (and a replay of the record)
cl_threads() {
    cl_frames "$CL/t.in" 300 14 640 480 rep
    cl_run "$BIN" t.in t1.rec LENSMAT_THREADS=1 || return 1
    mv "$CL/rep.txt" "$CL/rep1.txt"
    cl_run "$BIN" t.in t2.rec LENSMAT_THREADS=2 || return 1
    grep -q '^Times (1 threads)' "$CL/t1.rec.out" && grep -q '^Times (2 threads)' "$CL/t2.rec.out" &&
        cmp "$CL/t1.rec" "$CL/t2.rec" && cmp "$CL/rep1.txt" "$CL/rep.txt" &&
        grep -q '^Tracer check' "$CL/rep.txt" && grep -q '^Spots: 300 fitted' "$CL/rep.txt"
}
check "cornea loop: record and report byte-identical with 1 and 2 threads" cl_threads
cl_replay() {
    grep '^input:' "$CL/t1.rec" | sed 's/^input: //; s/^rep$/rep3/' > "$CL/t3.in" &&
        cl_run "$BIN" t3.in t3.rec && cmp "$CL/rep1.txt" "$CL/rep3.txt" &&
        [ "$(grep -v '^input' "$CL/t1.rec")" = "$(grep -v '^input' "$CL/t3.rec")" ]
}
check "cornea loop: the grep'd record replays to the same report" cl_replay
# 3. spots off the sensor or cut by its edge: rejected, counted, each listed with why
cl_offsensor() {
    cl_frames "$CL/o.in" 300 12 640 480 -
    cl_run "$BIN" o.in o.rec || { cat "$CL/o.rec.err"; return 1; }
    n=$(awk '/^Spots:/ { print $4 }' "$CL/o.rec")
    off=$(grep -c '^Rejected: point .*: no spot: it lands off the sensor' "$CL/o.rec")
    edge=$(grep -c '^Rejected: point .*: the spot at pixel .* is cut by the sensor.s edge' "$CL/o.rec")
    [ "$off" -gt 10 ] && [ "$edge" -gt 0 ] && [ "$n" -eq $((off + edge)) ] &&
        grep -q "^Spots: $((300 - n)) fitted, $n rejected ($n no spot" "$CL/o.rec" &&
        grep -q '^Tracer check: .*agrees' "$CL/o.rec"
}
check "cornea loop: spots off or cut by a smaller sensor rejected and listed with the reason" cl_offsensor
# every spot off the sensor (5 um pixels: the frame is 3.2 x 2.4 mm, the eye's spots
# land 2.3-3.1 mm away): the fit has nothing, a replay fails with a message
cl_allout() {
    cl_frames "$CL/a.in" 30 5 640 480 arep
    ! cl_run "$BIN" a.in a.rec && grep -q '^Spots from' "$CL/a.rec" &&
        grep -q '^The fit failed' "$CL/a.rec" && [ ! -e "$CL/arep.txt" ] && [ ! -e "$CL/arep.csv" ]
}
check "cornea loop: every spot off the sensor: the fit fails, exit non-zero, no report" cl_allout
# 4. patterns: rings and grid give the points asked for
cl_patterns() {
    for p in rings grid; do
        cl_frames "$CL/p$p.in" 100 14 640 480 - $p
        cl_run "$BIN" "p$p.in" "p$p.rec" || return 1
        grep -q "^Pattern $p: 100 targets to 12 deg, 100 planned" "$CL/p$p.rec" || return 1
        grep -q '^Spots: 100 fitted' "$CL/p$p.rec" || return 1
    done
}
check "cornea loop: rings and grid patterns, 100 points each, fitted" cl_patterns
# 5. the check of the fit's analytic model against the tracer: a tolerance it cannot
# meet (0 um) fails the session, says so, writes no report
cl_checkfail() {
    cl_frames "$CL/c.in" 100 14 640 480 crep
    ! cl_run "$BIN" c.in c.rec LENSMAT_CORNEA_CHECK_TOL_UM=0 &&
        grep -q '^Tracer check: .*(tolerance 0 um): DISAGREES' "$CL/c.rec" &&
        grep -q 'disagrees with the tracer by' "$CL/c.rec.err" && [ ! -e "$CL/crep.txt" ] && [ ! -e "$CL/crep.json" ]
}
check "cornea loop: the tracer check failing its tolerance is an error (exit 2, no report)" cl_checkfail
# 6. the quick model source: no OpenCV mapped; frames map it (LD_DEBUG=files)
cl_maps() {
    printf 'biconic\n-\nspiral\n30\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n1\n0\n-\n' > "$CL/m.in"
    cl_run "$BIN" m.in m.rec LD_DEBUG=files || return 1
    grep -q '^Spots: the traced hit plus Gaussian noise' "$CL/m.rec" &&
        grep -q 'lensmat-trace' "$CL/m.rec.err" && ! grep -q -E 'opencv|lensmat-imaging' "$CL/m.rec.err" || return 1
    cl_frames "$CL/f.in" 30 14 640 480 -
    cl_run "$BIN" f.in f.rec LD_DEBUG=files && grep -q 'libopencv_core' "$CL/f.rec.err"
}
check "cornea loop: the model source maps no OpenCV, frames do" cl_maps
# 7. on the simulated chip: move, expose, frame per point; the log ends laser off
cl_sim() {
    printf 'biconic\n%s\nsim\nsim.log\n2\nspiral\n30\n4\nframes\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-\n1\n0\nsrep\nn\n' \
        "$RIGGOLD" > "$CL/s.in"
    cl_run "$BIN" s.in s.rec || { cat "$CL/s.rec.err"; return 1; }
    grep -q '^Pattern spiral: 30 targets to 4 deg, 30 planned, 30 exposed' "$CL/s.rec" &&
        [ "$(grep -c ' laser 1' "$CL/sim.log")" -eq 30 ] &&
        grep -q 'final laser=0 light=0 enable=000000 .* violations=0' "$CL/sim.log" &&
        ! grep -q VIOLATION "$CL/sim.log" && grep -q '^Spots: 30 fitted' "$CL/srep.txt"
}
check "cornea loop: a 30-point scan on the simulated chip (30 exposures, laser off at the end)" cl_sim
# the scan's dose in the record, against an independent model: a Gaussian beam of
# power P and 1/e^2 diameter d averaged over the 7 mm aperture, the MPE 18 t^0.75 J/m^2
# (IEC 60825-1 Table A.1, 400-700 nm) for the summed on-time
cl_dose() {
    line=$(grep '^Dose: ' "$CL/s.rec") || { echo "no Dose line"; return 1; }
    echo "$line" | awk '{
        n = $2; t = $5 / 1e3; P = $8 / 1e3; d = $12 / 1e3; H1 = $15; Ht = $18
        for (i = 1; i <= NF; i++) { if ($i == "limit") mpe = $(i + 1); if ($i == "of" && $(i + 1) == "the") f = $(i - 1) }
        a = 3.5e-3; w = d / 2
        e1 = P * (1 - exp(-2 * a * a / (w * w))) / (3.14159265358979 * a * a) * t
        m = 18 * (n * t) ^ 0.75
        ok = (H1 / e1 - 1) ^ 2 < 1e-6 && (Ht / (n * e1) - 1) ^ 2 < 1e-6 && (mpe / m - 1) ^ 2 < 1e-6 &&
             (f / (n * e1 / m) - 1) ^ 2 < 1e-4
        if (!ok) printf "got H1 %s Ht %s mpe %s f %s; want %g %g %g %g\n", H1, Ht, mpe, f, e1, n * e1, m, n * e1 / m
        exit !ok }'
}
check "cornea loop: the scan's dose and its margin in the record, as an independent model gives them" cl_dose
# 8. SIGTERM mid-scan on the simulated chip: exit 143, the laser off, drivers disabled,
# no report (nor its .part) and the simulator's log complete
cl_term() {
    printf 'biconic\n%s\nsim\nk.log\n2\nspiral\n10000\n4\nframes\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-\n1\n0\nkrep\nn\n' \
        "$RIGGOLD" > "$CL/k.in"
    (cd "$CL" && exec "$BIN" --cornea-scan -i k.in k.rec > k.out 2> k.err) &
    p=$!
    # (mid-scan: once the simulator's log, still LOG.part.XXXXXX, shows a pulse; the
    # scan first plans its order, doc/scan-time.md)
    i=0
    while [ $i -lt 300 ] && ! cat "$CL"/k.log.part.* 2> /dev/null | grep -q ' laser 1'; do
        sleep 0.1; i=$((i + 1))
    done
    sleep 0.1
    kill -TERM "$p"
    wait "$p"
    rc=$?
    [ "$rc" -eq 143 ] || { echo "exit $rc"; cat "$CL/k.err"; return 1; }
    [ ! -e "$CL/krep.txt" ] && [ ! -e "$CL/krep.txt.part" ] && [ ! -e "$CL/krep.csv" ] && [ ! -e "$CL/k.log.part" ] &&
        grep -q 'final laser=0 light=0 enable=000000' "$CL/k.log" && ! grep -q VIOLATION "$CL/k.log" &&
        [ "$(grep -c ' laser 1' "$CL/k.log")" -gt 0 ] && [ "$(grep -c ' laser 1' "$CL/k.log")" -lt 10000 ] &&
        ! grep -q '^Errors' "$CL/k.out"
}
check "cornea loop: SIGTERM mid-scan: exit 143, laser off, no report under its name" cl_term
# 9. the sanitizer build: the same record as the normal build
cl_asan() {
    [ -x "$ASAN" ] || return 1
    cl_frames "$CL/z.in" 100 14 640 480 -
    cl_run "$BIN" z.in z1.rec && cl_run "$ASAN" z.in z2.rec LENSMAT_LIBDIR="$TOP/build/asan/lib" &&
        cmp "$CL/z1.rec" "$CL/z2.rec"
}
check "cornea loop: ASan build, frames and fit, the same record" cl_asan
# 10. frames saved by a synthetic scan, then measured as a camera's (numbered files):
# the same spots found (the noise now measured from each frame), the same cornea to
# well within its uncertainty; no eye questions, no errors against a truth
cl_camera() {
    rm -f "$CL"/fr*.png
    cl_frames "$CL/sv.in" 30 14 640 480 - spiral 'fr%04d.png'
    cl_run "$BIN" sv.in sv.rec || { cat "$CL/sv.rec.err"; return 1; }
    [ "$(ls "$CL"/fr*.png | wc -l)" -eq 30 ] && grep -q '^Frames saved as fr%04d.png (numbered 1 to 30)' "$CL/sv.rec" || return 1
    printf 'biconic\n-\nspiral\n30\n12\ncamera\nfr%%04d.png\n14\ncrep2\nn\n' > "$CL/cam.in"
    cl_run "$BIN" cam.in cam.rec || { cat "$CL/cam.rec.err"; return 1; }
    grep -q '^Camera: frames from fr%04d.png' "$CL/cam.rec" && grep -q '^Spots: 30 fitted' "$CL/cam.rec" &&
        ! grep -q -e '^Errors' -e 'simulated eye' "$CL/cam.rec" && grep -q '^Tracer check: .*agrees' "$CL/cam.rec" &&
        awk 'FNR == 1 { f++ } /^apex radius R/ { r[f] = $4; s[f] = $6 }
             END { d = r[1] - r[2]; exit !(d < 0.2 * s[1] && d > -0.2 * s[1]) }' "$CL/sv.rec" "$CL/cam.rec"
}
check "cornea loop: saved frames measured again as a camera's: the same cornea" cl_camera
# a frame missing: the camera gave fewer frames than exposures, exit 2, no report
cl_camera_short() {
    rm -f "$CL/fr0030.png" "$CL/crep2.txt"
    ! cl_run "$BIN" cam.in cam2.rec && grep -q 'fr%04d.png gave 29 frames for 30 exposures' "$CL/cam2.rec" &&
        [ ! -e "$CL/crep2.txt" ] && ! grep -q '^Spots: ' "$CL/cam2.rec" && grep -q 'gave 29 frames' "$CL/cam2.rec.err"
}
check "cornea loop: a camera with fewer frames than exposures is an error" cl_camera_short
# SIGTERM while the frames are made and saved (no machine): exit 143, no report, no
# half-written frame (each is written to a temporary name and renamed)
cl_term_frames() {
    mkdir -p "$CL/tf" && rm -f "$CL"/tf/*
    cl_frames "$CL/tf.in" 10000 14 640 480 tf/rep spiral 'tf/g%05d.png'
    (cd "$CL" && exec "$BIN" --cornea-scan -i tf.in tf.rec > tf.out 2> tf.err) &
    p=$!
    sleep 1
    kill -TERM "$p"
    wait "$p"
    rc=$?
    [ "$rc" -eq 143 ] || { echo "exit $rc"; cat "$CL/tf.err"; return 1; }
    n=$(ls "$CL/tf" | grep -c '^g[0-9]*\.png$')
    [ ! -e "$CL/tf/rep.txt" ] && [ "$n" -gt 0 ] && [ "$n" -lt 10000 ] &&
        [ "$(ls "$CL/tf" | grep -v '^g[0-9]*\.png$' | grep -vx 'g-frames.txt' | wc -l)" -eq 0 ] &&
        ! grep -q '^Spots: ' "$CL/tf.out" &&
        grep -q '^scan interrupted (signal 15)' "$CL/tf/g-frames.txt"    # its frames' list
}
check "cornea loop: SIGTERM while frames are saved: exit 143, no report, no half-written frame" cl_term_frames
# 11. the same loop on the kernel's gpio-sim chip in qemu (../shared/tools/gpio-vm/run;
# tests/cornea/vm_scan.sh inside the guest): a 10-point scan moved and exposed through
# libgpiod, fitted, the laser low afterwards, the record replaying to the same report
cl_vm() {
    vm=${GPIO_VM:-$SHARED/tools/gpio-vm/run}
    [ -x "$vm" ] || { echo "gpio-vm: $vm not found"; return 1; }
    mkdir -p "$CL/vmlibs"
    for l in $(ldd "$BIN" | grep -o '/[^ ]*libreadline[^ ]*'); do cp -L "$l" "$CL/vmlibs/"; done
    (cd "$TOP" && GPIO_VM_FILES="tests/cornea/vm_scan.rig lensmat build/lib/lensmat-rig.so build/lib/lensmat-trace.so build/lib/lensmat-cornea.so build/lib/lensmat-topo.so $CL/vmlibs" \
        "$vm" tests/cornea/vm_scan.sh) > "$CL/vm.out" 2>&1
    rc=$?
    tr -d '\r' < "$CL/vm.out" | grep -E '^(PASS|FAIL)'
    [ "$rc" -eq 0 ] && [ "$(tr -d '\r' < "$CL/vm.out" | grep -c '^PASS')" -eq 7 ]
}
check "cornea loop: a 10-point scan on the gpio-sim chip (libgpiod), replayed" cl_vm
