# t_92_cornea_maps.sh -- the cornea measurement's files (issue 12): --cornea-scan's
# report (text, CSV and JSON, every number, the rejected spots) and maps (PNG through
# the imaging engine, written via .part), from the model's spots and from synthetic
# frames' centroids, replayed from the record to the same report,
# outputs that would overwrite an input refused, the compare script, and the
# many-eyes study under GNU parallel, here and over two fake hosts (skipped with a
# message when parallel or rsync is missing).
cm_in() {   # model points name maps(y/n) [seed] -> answers (the example geometry, a
            # spiral, spots from the model: the traced hit plus 0.04 px; no cone)
    printf '%s\n-\nspiral\n%s\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n%s\n0\n%s\n%s\n' \
        "$1" "$2" "${5:-1}" "$3" "$4"
}
mkdir -p "$WORK/cm"
# the imaging engine's map drawing (tests/imaging/t_map.c), normal and sanitizer builds
for kind in obj asan; do
    lib=$TOP/build/lib; [ "$kind" = asan ] && lib=$TOP/build/asan/lib
    bin=$TOP/build/$kind/imaging_tests/t_map
    if [ ! -x "$bin" ]; then fail "$bin (not built)"; continue; fi
    d=$(mktemp -d "$WORK/map.XXXXXX")
    (cd "$TOP" && IM_LIBDIR=$lib LSAN_OPTIONS="suppressions=$TOP/tests/imaging/lsan.supp:fast_unwind_on_malloc=0:print_suppressions=0" "$bin" "$d") > "$WORK/unit.out" 2>&1; rc=$?
    p=$(grep -c '^PASS' "$WORK/unit.out"); f=$(grep -c '^FAIL' "$WORK/unit.out")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$WORK/unit.out" | sed "s|^|$kind/t_map: |"
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then fail "$kind/t_map exited $rc"; tail -20 "$WORK/unit.out"; fi
done
cm_maps() {
    cd "$WORK/cm" && rm -f eye* && cm_in biconic 300 eye y > a.in &&
    "$TOP/lensmat" --cornea-scan a.rec < a.in > a.out 2> a.err || { cat a.err; return 1; }
    for s in .txt .csv .json -elevation.png -axial.png -tangential.png -residual.png; do
        [ -s "eye$s" ] || { echo "no eye$s"; return 1; }
    done
    ! ls | grep -q '\.part' || { echo "a .part file left"; return 1; }
    for s in elevation axial tangential residual; do   # PNG signature
        [ "$(head -c 8 eye-$s.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
            { echo "eye-$s.png is not a PNG"; return 1; }
    done
    grep -q '^Axial curvature: .* in 0.25 D steps: eye-axial.png' a.out &&
    grep -q '^Tangential curvature: .* in 0.\(25\|5\) D steps' a.out &&
    grep -q '^Report written: eye.txt, eye.csv and eye.json' a.out &&
    grep -q '^Axial curvature: .*eye-axial.png' eye.txt && grep -q '^Spots: 300 fitted' eye.txt ||
        { cat a.out; return 1; }
}
check "--cornea-scan writes the report (text, CSV, JSON) and four maps (PNG, no .part left, 0.25 D steps)" cm_maps
cm_csv() {
    cd "$WORK/cm" &&
    awk -F, 'NF != 4 { print "row " NR " has " NF " fields: " $0; bad = 1 } END { exit bad }' eye.csv &&
    for q in model R Q K1 K1_axis K2 Km cyl P zK1 zK2 zKm zcyl rms chi2_dof param_A4 \
             sv_0 true_R err_R err_Km err_axis; do
        grep -q "^$q," eye.csv || { echo "no $q row"; return 1; }
    done
    # the report's numbers are the printed ones
    km=$(awk -F, '$1 == "Km" { printf "%.3f", $2 }' eye.csv)
    grep -q "^mean K $km +- " a.out || { echo "Km $km not in the output"; return 1; }
    python3 -c 'import json,sys; d=json.load(open("eye.json")); sys.exit(0 if d["clinical"]["zKm"]["value"] > 40 and d["dialogue"]["err_R"]["unit"] == "um" and d["model"] == "biconic" else 1)'
}
check "report: CSV rows of quantity,value,sd,unit with Sim K (apex, 3 mm zone), truth and errors; JSON parses" cm_csv
cm_replay() {
    cd "$WORK/cm" && mkdir -p re && grep '^input:' a.rec | sed 's/^input: //' > re/a.in &&
    (cd re && "$TOP/lensmat" --cornea-scan a.rec < a.in > a.out 2>&1) &&
    cmp eye.csv re/eye.csv && cmp eye.json re/eye.json && cmp a.rec re/a.rec &&
    cmp eye-axial.png re/eye-axial.png && cmp eye-residual.png re/eye-residual.png
}
check "the record replays to the same report, record and maps, byte for byte" cm_replay
cm_asan() {
    cd "$WORK/cm" && mkdir -p asan && cd asan && cp ../a.in . &&
    LSAN_OPTIONS="suppressions=$TOP/tests/imaging/lsan.supp:fast_unwind_on_malloc=0:print_suppressions=0" \
        "$TOP/build/asan/lensmat" --cornea-scan a.rec < a.in > a.out 2> a.err || { cat a.err; return 1; }
    cmp ../eye.csv eye.csv && cmp ../eye.json eye.json && cmp ../eye-axial.png eye-axial.png &&
    cmp ../eye-residual.png eye-residual.png && ! grep -q 'Sanitizer' a.err
}
check "the sanitizer build writes the same report and maps (ASan/UBSan clean)" cm_asan
cm_refuse() {
    cd "$WORK/cm" && cm_in conic 100 a n > a.csv.in && cp a.csv.in a.csv &&
    if "$TOP/lensmat" --cornea-scan b.rec < a.csv > b.out 2> b.err; then
        echo "accepted a report over its answers file"; return 1; fi
    cmp -s a.csv a.csv.in && grep -q '<stdin>:19: .*a.csv is the file the answers are read from' b.err || { cat b.err; return 1; }
    cm_in conic 100 b n > b.in &&
    if "$TOP/lensmat" --cornea-scan b.csv < b.in > b.out 2> b.err; then
        echo "accepted a report over the record"; return 1; fi
    grep -q '<stdin>:19: .*b.csv' b.err || { cat b.err; return 1; }
}
check "a report name whose files would overwrite the answers or the record is refused in a replay (FILE:LINE)" cm_refuse
cm_asphere() {   # a rotational eye (no cylinder), so the asphere is the right model
    cd "$WORK/cm" && cm_in asphere 300 asph n | sed '9s/.*/0/' > c.in &&
    "$TOP/lensmat" --cornea-scan c.rec < c.in > c.out 2> c.err &&
    grep -q '^asphere A4 .* (Q held)' c.out && grep -q '^model,asphere,' asph.csv &&
    grep -q '^Tracer check: .*: agrees' c.out &&
    awk -F, '$1 == "err_R" { exit !($2 < 1 && $2 > -1) }' asph.csv &&
    grep -q '^param_A4,[^,]*,[0-9.e-]*,mm^-3$' asph.csv && [ ! -e asph-axial.png ]
}
check "--cornea-scan fits the even asphere (A4, A6 about the held Q), report without maps" cm_asphere
cm_compare() {
    cd "$WORK/cm" && cm_in biconic 300 s2 n 2 > d.in &&
    "$TOP/lensmat" --cornea-scan d.rec < d.in > d.out 2>&1 &&
    "$TOP/scripts/cornea-compare.sh" eye.csv s2.csv > cmp1.out || { cat cmp1.out; return 1; }
    grep -q '^Km ' cmp1.out && ! grep -q DIFFERS cmp1.out &&
    printf 'biconic\n-\nspiral\n300\n12\nmodel\n7.83\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n3\n0\ns3\nn\n' > e.in &&
    "$TOP/lensmat" --cornea-scan e.rec < e.in > e.out 2>&1 &&
    if "$TOP/scripts/cornea-compare.sh" eye.csv s3.csv > cmp2.out; then
        echo "a 30 um radius change not flagged"; cat cmp2.out; return 1; fi
    grep -q '^R .*DIFFERS' cmp2.out && grep -q '^Km .*DIFFERS' cmp2.out
}
check "cornea-compare.sh: two seeds of one eye agree, an eye 30 um flatter DIFFERS (exit 1)" cm_compare
cm_cone() {
    cd "$WORK/cm" &&
    printf 'biconic\n-\nspiral\n500\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n5\n1\n10\n0.8\n0.4\n-0.7\ncone\ny\n' > f.in &&
    "$TOP/lensmat" --cornea-scan f.rec < f.in > f.out 2>&1 || { cat f.out; return 1; }
    grep -q '^POOR FIT' f.out && grep -q '^SYSTEMATIC RESIDUALS: neighbour correlation 0\.[5-9]' f.out &&
    grep -q '^the model is rejected: R, Q, K, cylinder, power and the eye.s pose not reported' f.out &&
    ! grep -q '^mean K' f.out && grep -q '^model_rejected,1,' cone.csv && grep -q '^poor_fit,1,' cone.csv &&
    grep -q '^undetermined,R,' cone.csv && grep -q '^true_cone_h,10,' cone.csv &&
    awk -F, '$1 == "resid_corr" { exit !($2 > 0.5) }' cone.csv && [ -s cone-residual.png ] ||
        { cat f.out; return 1; }
    # the same eye without the cone: a good fit, residuals uncorrelated
    sed '18s/.*/0/; 19,21d; s/^cone$/nocone/' f.in > g.in &&
    "$TOP/lensmat" --cornea-scan g.rec < g.in > g.out 2>&1 && ! grep -q 'POOR FIT' g.out &&
    awk -F, '$1 == "resid_corr" { exit !($2 < 0.2 && $2 > -0.2) }' nocone.csv
}
check "a keratoconus-like cone: the model is rejected, none of its numbers printed (POOR, systematic residuals); without it a good fit" cm_cone
# the same files from synthetic frames' centroids (and with a cone on the eye: its spots
# through the analytic model, then framed and located like any other)
cm_frames() {
    cd "$WORK/cm" && rm -f fr* &&
    printf 'biconic\n-\nspiral\n300\n12\nframes\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\n-\n1\n0\nfr\ny\n' > h.in &&
    "$TOP/lensmat" --cornea-scan h.rec < h.in > h.out 2>&1 || { cat h.out; return 1; }
    for s in .txt .csv .json -elevation.png -axial.png -tangential.png -residual.png; do
        [ -s "fr$s" ] || { echo "no fr$s"; return 1; }
    done
    grep -q '^Frames: 640x480' fr.txt && grep -q '^spots_fitted,300,' fr.csv &&
    grep -q '^scan_source,0,' fr.csv && awk -F, '$1 == "err_R" { exit !($2 < 8 && $2 > -8) }' fr.csv &&
    grep -q '^Axial curvature: .* in 0.25 D steps: fr-axial.png' h.out || { cat h.out; return 1; }
    sed '20s/.*/10/; 20a\
0.8\
0.4\
-0.7
s/^fr$/frc/' h.in > k.in &&
    "$TOP/lensmat" --cornea-scan k.rec < k.in > k.out 2>&1 || { cat k.out; return 1; }
    grep -q '^Cone: 10 um high' k.out && grep -q '^SYSTEMATIC RESIDUALS' k.out &&
    grep -q '^true_cone_h,10,' frc.csv && [ -s frc-residual.png ] || { cat k.out; return 1; }
}
check "report and maps from synthetic frames' centroids, with and without a cone" cm_frames
cm_stop() {
    cd "$WORK/cm" && cm_in biconic 10000 stopped y > s.in &&
    (exec "$TOP/lensmat" --cornea-scan s.rec < s.in > s.out 2> s.err) &
    p=$!
    sleep 0.4
    kill -INT "$p"
    wait "$p"
    rc=$?
    [ "$rc" -eq 130 ] || { echo "exit $rc"; cat "$WORK/cm/s.err"; return 1; }
    ! ls "$WORK/cm" | grep -q '^stopped' || { ls "$WORK/cm"; return 1; }
}
check "SIGINT mid-fit with a report asked: exit 130, no report, map or .part file" cm_stop
if command -v parallel >/dev/null 2>&1 && parallel --version 2>/dev/null | grep -q 'GNU parallel'; then
    cm_study() {
        d="$WORK/cm/study"
        "$TOP/scripts/cornea-study.sh" -M 6 -p 100 -s 7 -j 2 -o "$d" > "$WORK/cm/study.log" 2>&1 ||
            { cat "$WORK/cm/study.log"; return 1; }
        [ "$(ls "$d"/eye-*.csv | wc -l)" -eq 6 ] && [ "$(wc -l < "$d/study.tsv")" -eq 7 ] &&
        awk -F'\t' '$1 == "R" && $2 == "um" && $3 == 6 && $4 > 0 && $4 < 20 { ok = 1 } END { exit !ok }' \
            "$d/percentiles.tsv" &&
        grep -q '^Km ' "$WORK/cm/study.log" && [ -s "$d/study.png" ] || { cat "$WORK/cm/study.log"; return 1; }
        # every eye replays from its record to the same report
        mkdir -p "$d/re" && grep '^input:' "$d/eye-0004.rec" | sed 's/^input: //' > "$d/re/in" &&
        (cd "$d/re" && "$TOP/lensmat" --cornea-scan eye-0004.rec < in > out 2>&1) &&
        cmp "$d/eye-0004.csv" "$d/re/eye-0004.csv" || return 1
        # the same seed draws the same eyes; another seed others
        "$TOP/scripts/cornea-study.sh" -M 6 -p 100 -s 7 -j 1 -o "$d.b" > /dev/null 2>&1 &&
        cmp "$d/study.tsv" "$d.b/study.tsv" &&
        "$TOP/scripts/cornea-study.sh" -M 2 -p 100 -s 8 -o "$d.c" > /dev/null 2>&1 &&
        ! cmp -s "$d/eye-0001.in" "$d.c/eye-0001.in"
    }
    check "cornea-study.sh: 6 eyes under GNU parallel, one table, percentiles, plot; replayable, seeded" cm_study
    # several hosts without a network: tests/cornea/fake-ssh stands in for ssh (and for
    # rsync's remote shell), each fake host a home of its own, so the eyes' files really
    # go out and come back through parallel's --trc; lensmat installed into a prefix
    # (make install), as on a real host, not this build tree
    cm_hosts() {
        d="$WORK/cm/study" h="$WORK/cm/hosts" pfx="$WORK/cm/remote-prefix"
        rm -rf "$h" "$d.r" && mkdir -p "$h" &&
        make -s -C "$TOP" install PREFIX="$pfx" > "$WORK/cm/install.log" 2>&1 ||
            { cat "$WORK/cm/install.log"; return 1; }
        # the stand-in is honest: a job that was sent nothing finds nothing
        if (cd "$d" && FAKE_SSH_ROOT=$h parallel --ssh "$TOP/tests/cornea/fake-ssh" -S 1/fakehost0 \
                'cat {}' ::: eye-0001.in) > /dev/null 2>&1; then
            echo "fake-ssh ran in this folder, not the fake host's"; return 1; fi
        FAKE_SSH_ROOT=$h PARALLEL_SSH=$TOP/tests/cornea/fake-ssh LENSMAT=$pfx/bin/lensmat \
            "$TOP/scripts/cornea-study.sh" -M 6 -p 100 -s 7 -j 1 -S 1/fakehost1,1/fakehost2 -o "$d.r" \
            > "$WORK/cm/hosts.log" 2>&1 || { cat "$WORK/cm/hosts.log"; return 1; }
        cmp "$d/study.tsv" "$d.r/study.tsv" || return 1
        for f in "$d"/eye-*.csv "$d"/eye-*.json "$d"/eye-*.rec "$d"/eye-*.txt; do
            cmp "$f" "$d.r/${f##*/}" || return 1
        done
        # both hosts ran eyes (none here), the answers went out and the files came back
        # by rsync over the stand-in, and --cleanup left both homes empty
        awk -F'\t' 'NR > 1 { n[$2]++; if ($5 <= 0 || $6 <= 0) bad = 1 }
            END { exit bad || n["fakehost1"] < 1 || n["fakehost2"] < 1 || n["fakehost1"] + n["fakehost2"] != 6 }' \
            "$d.r/joblog.txt" || { cat "$d.r/joblog.txt"; return 1; }
        grep -q '^rsync --server -' "$h/fakehost1.log" && grep -q '^cd .*rsync --server --sender' "$h/fakehost2.log" &&
        grep -q '^exec perl ' "$h/fakehost2.log" || { cat "$h"/*.log; return 1; }
        [ -z "$(find "$h/fakehost1" "$h/fakehost2" -mindepth 1)" ] || { ls -laR "$h"; return 1; }
    }
    if command -v rsync >/dev/null 2>&1; then
        check "cornea-study.sh -S over 2 fake hosts (fake-ssh, rsync, installed lensmat): the same table and reports, homes cleaned" cm_hosts
    else
        echo "SKIP t_92 study over several hosts: rsync is not installed (scripts/install-deps.sh)"
    fi
else
    echo "SKIP t_92 many-eyes study: GNU parallel is not installed (scripts/install-deps.sh)"
fi
