# t_52_outputs.sh -- how lensmat writes files (doc/outputs.md, src/common/lm_out.c).
# Every writer (trace summary and hits, --draw pictures, --spot frames, --cornea-scan
# reports and frames, the rig simulator's log, the three converters' OUTFILE) against
# a FIFO read by a background cat, a character node made with mknod (like /dev/null),
# a symbolic link to a regular file (the link stays, its target gets the output), a
# dangling link, /dev/full (the error is reported, exit 2, no "Written") and a
# read-only folder (exit 2, nothing left behind); two concurrent traces of one file;
# converters whose run fails leave an old OUTFILE byte for byte; write errors on
# standard output; OUTFILE -; escaped names; interrupted --spot streams and scans say
# where they stopped, and a scan's frames are listed in its manifest.
# The reference of each writer is its output to a plain new file in a fresh folder.
OW=$WORK/outputs
mkdir -p "$OW"
# the writer alone (tests/unit_out.c): modes, inodes, parts, links, devices, long names
unit "$TOP/build/obj/unit_out"
unit "$TOP/build/asan/unit_out"
RX52=$TOP/doc/triplet.rx
RIG52=$TOP/golden/rig/example.rig

# writer W DIR NAME: run writer W in DIR with its output named NAME; lensmat's status.
# Stdout and stderr in DIR/W.out, DIR/W.err.
writer() {
    w=$1; d=$2; nm=$3
    mkdir -p "$d"
    case $w in
    summary|hits)
        sed '/^output/d' "$TOP/scenes/singlet.scene" > "$d/s52.scene"
        echo "output $w $nm" >> "$d/s52.scene"
        printf 'scene\ns52.scene\nn\n' > "$d/$w.in" ;;
    draw)       # (NAME.svg is written beside NAME.png)
        printf '%s\n2.8\nmm\n10\n0.5\n0.8\nlayout\n%s\ndone\n' "$GOLDEN/cases/thick_r3_r4.in" "$nm" > "$d/$w.in" ;;
    spot)
        printf 'synth\n64\n48\n16\n32.3\n24.6\n3\n1000\n100\n50\n1\ny\n%s\n5\nn\n' "$nm" > "$d/$w.in" ;;
    report)     # NAME.txt is the file tested (the report's first)
        printf 'biconic\n-\nspiral\n10\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n1\n14\n1\n0\n%s\nn\n' \
            "${nm%.txt}" > "$d/$w.in" ;;
    rig)
        printf '%s\nsim\n%s\nhome\nquit\n' "$RIG52" "$nm" > "$d/$w.in" ;;
    to-zmx|to-thickness)
        (cd "$d" && "$BIN" --$w -i "$RX52" "$nm" > $w.out 2> $w.err); return $? ;;
    to-prescription)
        (cd "$d" && "$BIN" --$w -i "$GOLDEN/cases/thick_r3_r4.in" "$nm" > $w.out 2> $w.err); return $? ;;
    esac
    case $w in summary|hits) dlg=--trace ;; report) dlg=--cornea-scan ;; *) dlg=--$w ;; esac
    (cd "$d" && timeout 60 "$BIN" $dlg -i $w.in r52.rec > $w.out 2> $w.err)
}
# the name each writer's output takes (pictures and frames need their suffix)
out_name() {
    case $1 in draw|spot) echo "$2.png" ;; report) echo "$2.txt" ;; *) echo "$2" ;; esac
}
WRITERS="summary hits draw spot report rig to-zmx to-thickness to-prescription"
for w in $WRITERS; do
    writer $w "$OW/ref/$w" "$(out_name $w ref)" || echo "t_52: the reference run of $w failed: $(cat "$OW/ref/$w/$w.err")"
done
REF52=$OW/ref
ref_of() { echo "$REF52/$1/$(out_name $1 ref)"; }
# the reference run: a plain file, exit 0 (or the rest means nothing)
ref_ok() { [ -s "$(ref_of $1)" ]; }

# release DIR NAME: a reader still waiting on the FIFO (the writer never opened it)
# gets a writer that closes at once (read-write: never blocks)
release() { sh -c 'exec 3<> "$1"' _ "$1/$2" 2>/dev/null; }
w_fifo() {
    w=$1; d=$OW/fifo/$w; nm=$(out_name $w f); mkdir -p "$d"
    ref_ok $w || return 1
    mkfifo "$d/$nm" || return 1
    timeout 60 cat "$d/$nm" > "$d/got" & cpid=$!
    writer $w "$d" "$nm"; rc=$?
    release "$d" "$nm"; wait $cpid
    [ "$rc" -eq 0 ] || { echo "exit $rc"; cat "$d/$w.err"; return 1; }
    [ -p "$d/$nm" ] || { echo "the FIFO was replaced:"; ls -l "$d"; return 1; }
    cmp "$d/got" "$(ref_of $w)" || { echo "what the FIFO carried differs from the file"; return 1; }
    [ -z "$(ls "$d" | grep '\.part')" ] || { echo "left behind:"; ls "$d"; return 1; }
}
w_node() {
    w=$1; d=$OW/node/$w; nm=$(out_name $w mynull); mkdir -p "$d"
    mknod "$d/$nm" c 1 3 2>/dev/null || { echo "SKIP mknod failed (not root?)"; return 0; }
    writer $w "$d" "$nm"; rc=$?
    [ "$rc" -eq 0 ] || { echo "exit $rc"; cat "$d/$w.err"; return 1; }
    [ -c "$d/$nm" ] && [ "$(stat -c '%t,%T' "$d/$nm")" = "1,3" ] ||
        { echo "the node was replaced:"; ls -l "$d"; return 1; }
}
w_link() {
    w=$1; d=$OW/link/$w; nm=$(out_name $w l); mkdir -p "$d"
    ref_ok $w || return 1
    echo "the old target" > "$d/target"
    ln -s target "$d/$nm"
    writer $w "$d" "$nm"; rc=$?
    [ "$rc" -eq 0 ] || { echo "exit $rc"; cat "$d/$w.err"; return 1; }
    [ -L "$d/$nm" ] && [ "$(readlink "$d/$nm")" = target ] || { echo "the link was replaced:"; ls -l "$d"; return 1; }
    cmp "$d/target" "$(ref_of $w)"
}
w_dangling() {
    w=$1; d=$OW/dangling/$w; nm=$(out_name $w l); mkdir -p "$d/sub"
    ref_ok $w || return 1
    ln -s sub/new "$d/$nm"
    writer $w "$d" "$nm"; rc=$?
    [ "$rc" -eq 0 ] || { echo "exit $rc"; cat "$d/$w.err"; return 1; }
    [ -L "$d/$nm" ] || { echo "the link was replaced:"; ls -l "$d"; return 1; }
    cmp "$d/sub/new" "$(ref_of $w)" && [ "$(ls "$d/sub")" = new ]
}
w_full() {
    w=$1; d=$OW/full/$w; nm=$(out_name $w full); mkdir -p "$d"
    ln -s /dev/full "$d/$nm"
    writer $w "$d" "$nm"; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc, want 2"; cat "$d/$w.err"; return 1; }
    # (--draw says it in its answer to the picture, on stdout and in the record)
    cat "$d/$w.err" "$d/$w.out" | grep -qi 'no space\|write error\|could not be written' ||
        { echo "no error said:"; cat "$d/$w.err"; return 1; }
    ! grep -q "Written: $nm\|written to file $nm\|Frame written to $nm\|Report written" "$d/$w.out" ||
        { echo "claims it was written"; return 1; }
    [ -c /dev/full ] && [ -L "$d/$nm" ]
}
w_readonly() {
    w=$1; d=$OW/ro/$w; mkdir -p "$d/ro"
    if [ "$(id -u)" = 0 ]; then chattr +i "$d/ro" 2>/dev/null || { echo "SKIP chattr failed"; return 0; }
    else chmod 555 "$d/ro"; fi
    writer $w "$d" "ro/$(out_name $w x)"; rc=$?
    chattr -i "$d/ro" 2>/dev/null; chmod 755 "$d/ro"
    [ "$rc" -eq 2 ] || { echo "exit $rc, want 2"; cat "$d/$w.err"; return 1; }
    [ -s "$d/$w.err" ] || { echo "no message"; return 1; }
    [ -z "$(ls -A "$d/ro")" ] || { echo "left behind:"; ls -A "$d/ro"; return 1; }
}
for w in $WRITERS; do
    check "outputs: $w into a FIFO: written in place, what it carries equals the file" w_fifo $w
    check "outputs: $w into a mknod character node: written in place, the node stays" w_node $w
    check "outputs: $w through a symlink: the link stays, its target gets the output" w_link $w
    check "outputs: $w through a dangling symlink: the target is made, the link stays" w_dangling $w
    check "outputs: $w into /dev/full: the error is said, exit 2, no Written" w_full $w
    check "outputs: $w into a read-only folder: exit 2 with a message, nothing left" w_readonly $w
done

# The same under ASan/UBSan (the sanitizer build with its modules), for the writers
# in each of the core, the trace, imaging and rig modules.
if [ -x "$ASAN" ] && [ -d "$TOP/build/asan/lib" ]; then
    OW52=$OW; BIN52=$BIN
    OW=$WORK/outputs-asan; BIN=$ASAN; LENSMAT_LIBDIR=$TOP/build/asan/lib; export LENSMAT_LIBDIR
    for w in summary hits spot rig to-zmx; do
        check "outputs (asan): $w into a FIFO" w_fifo $w
        check "outputs (asan): $w through a symlink" w_link $w
        check "outputs (asan): $w into /dev/full" w_full $w
        check "outputs (asan): $w into a read-only folder" w_readonly $w
    done
    OW=$OW52; BIN=$BIN52; unset LENSMAT_LIBDIR
else
    fail "outputs (asan): build/asan/lensmat or build/asan/lib not built"
fi

# Two traces writing the same hits file at once: one complete output, never a mix.
concurrent() {
    d=$OW/conc; mkdir -p "$d/a" "$d/b" "$d/both"
    for g in 101 121; do
        sed -e '/^output/d' -e "s/ grid 21/ grid $g/" "$TOP/scenes/singlet.scene" > "$d/g$g.scene"
        echo "output hits same.csv" >> "$d/g$g.scene"
    done
    (cd "$d/a" && printf 'scene\n../g101.scene\nn\n' | "$BIN" --trace ra.rec > /dev/null 2>&1) &&
    (cd "$d/b" && printf 'scene\n../g121.scene\nn\n' | "$BIN" --trace rb.rec > /dev/null 2>&1) || return 1
    for i in 1 2; do
        (cd "$d/both" && printf 'scene\n../g101.scene\nn\n' | "$BIN" --trace r1.rec > o1 2> e1; echo $? > rc1) &
        (cd "$d/both" && printf 'scene\n../g121.scene\nn\n' | "$BIN" --trace r2.rec > o2 2> e2; echo $? > rc2) &
        wait
        [ "$(cat "$d/both/rc1")" = 0 ] && [ "$(cat "$d/both/rc2")" = 0 ] ||
            { echo "round $i: exits $(cat "$d/both/rc1") $(cat "$d/both/rc2")"; cat "$d/both/e1" "$d/both/e2"; return 1; }
        cmp -s "$d/both/same.csv" "$d/a/same.csv" || cmp -s "$d/both/same.csv" "$d/b/same.csv" ||
            { echo "round $i: same.csv ($(wc -l < "$d/both/same.csv") lines) is neither run's output"; return 1; }
        [ -z "$(ls "$d/both" | grep part)" ] || { echo "left behind:"; ls "$d/both"; return 1; }
    done
}
check "outputs: two traces of one hits file at once leave one complete output (2 rounds)" concurrent

# A converter whose input is bad exits 2 and leaves an earlier OUTFILE as it was.
conv_fail() {
    d=$OW/convfail/$1; mkdir -p "$d"
    printf 'garbage\n' > "$d/bad"
    printf 'an earlier output\n' > "$d/old"; cp "$d/old" "$d/OUT"
    (cd "$d" && "$BIN" --$1 -i bad OUT > out 2> err); rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; return 1; }
    cmp "$d/OUT" "$d/old" && [ -s "$d/err" ] && [ "$(ls "$d")" = "$(printf 'OUT\nbad\nerr\nold\nout')" ]
}
for c in to-zmx to-thickness to-prescription; do
    check "outputs: --$c with a bad input: exit 2, the old OUTFILE byte for byte" conv_fail $c
done

# Standard output: a write error is said and exits 2.
full_stdout() {
    "$@" > /dev/full 2> "$OW/fs.err"; rc=$?
    [ "$rc" -eq 2 ] && grep -q 'standard output' "$OW/fs.err" || { echo "exit $rc"; cat "$OW/fs.err"; return 1; }
}
check "outputs: --help > /dev/full: said, exit 2" full_stdout "$BIN" --help
check "outputs: --version > /dev/full: said, exit 2" full_stdout "$BIN" --version
check "outputs: --example x.rec > /dev/full: said, exit 2" full_stdout "$BIN" --example "$OW/fsx.rec"
check "outputs: --thin --example > /dev/full: said, exit 2" full_stdout "$BIN" --thin --example "$OW/fsy.rec"
check "outputs: --to-zmx -i F - > /dev/full: said, exit 2" full_stdout "$BIN" --to-zmx -i "$RX52" -
check "outputs: lensmat alone: the usage, exit 1" sh -c "'$BIN' > '$OW/usage'; [ \$? -eq 1 ] && grep -q -- --help '$OW/usage'"

# OUTFILE -: standard output for the converters, refused (no file -) for a dialogue.
dash() {
    d=$OW/dash; mkdir -p "$d"
    (cd "$d" && "$BIN" --to-zmx -i "$RX52" - > got && "$BIN" --to-zmx -i "$RX52" file.zmx) &&
        cmp "$d/got" "$d/file.zmx" || return 1
    (cd "$d" && "$BIN" --thin - < /dev/null > o 2> e); rc=$?
    [ "$rc" -eq 1 ] && grep -q 'standard output' "$d/e" && [ ! -e "$d/-" ]
}
check "outputs: OUTFILE - is stdout for --to-zmx, refused with a message for --thin" dash

# "Output was written to file X" shows X's control bytes escaped.
escaped() {
    d=$OW/esc; mkdir -p "$d"
    name=$(printf 'a\033[2Jb.rec')
    (cd "$d" && "$BIN" --thin --example "$name" > out 2> err) || return 1
    grep -q 'Output was written to file a\\x1b\[2Jb.rec' "$d/out" && ! grep -q "$(printf '\033')" "$d/out"
}
check "outputs: the record's name in 'Output was written' has its control bytes escaped" escaped

# An interrupted --spot stream says after which frame, on stderr and in the record;
# its lines come as computed (the first is in the file while the stream still runs).
spot_stream_int() {
    d=$OW/stream; mkdir -p "$d"
    # one 512 x 512 frame, 3000 names for it: a stream far longer than the test
    printf 'synth\n512\n512\n16\n250.3\n240.6\n3\n1000\n100\n50\n1\ny\nbig.png\n5\nn\n' > "$d/mk.in"
    (cd "$d" && "$BIN" --spot -i mk.in mk.rec > /dev/null 2>&1) || return 1
    python3 -c 'import os,sys
for i in range(1, 3001): os.symlink("big.png", os.path.join(sys.argv[1], "f%05d.png" % i))' "$d" || return 1
    printf 'stream\nf%%05d.png\n1\n3000\n5\nn\n' > "$d/in"
    (cd "$d" && exec "$BIN" --spot -i in s.rec > out 2> err) & p=$!
    i=0; while ! grep -q '^Frame 1 ' "$d/out" 2>/dev/null && [ $i -lt 400 ]; do sleep 0.05; i=$((i+1)); done
    alive=0; kill -0 $p 2>/dev/null && alive=1
    kill -TERM $p 2>/dev/null; wait $p; rc=$?
    [ "$alive" = 1 ] || { echo "the first frame's line appeared only when the stream ended"; return 1; }
    [ "$rc" -eq 143 ] || { echo "exit $rc"; return 1; }
    grep -q 'lensmat: Interrupted after frame [0-9]* of 3000 (signal 15)' "$d/err" &&
        grep -q '^Interrupted after frame [0-9]* of 3000' "$d/s.rec" || { cat "$d/err"; tail -2 "$d/s.rec"; return 1; }
}
check "outputs: --spot stream: lines as computed; SIGTERM says after which frame (stderr, record)" spot_stream_int

# A scan interrupted while saving frames into a folder with an earlier scan's frames:
# its manifest lists only its own frames and says it was interrupted; stderr and the
# record say where; no report; its stdout lines come as computed.
scan_int() {
    d=$OW/scan; mkdir -p "$d/fr"
    printf 'biconic\n-\nspiral\n%s\n12\nframes\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n14\n640\n480\nfr/g%%04d.png\n1\n0\nrep\nn\n' 40 > "$d/a.in"
    (cd "$d" && "$BIN" --cornea-scan -i a.in a.rec > a.out 2> a.err) || { cat "$d/a.err"; return 1; }
    grep -q '^scan complete$' "$d/fr/g-frames.txt" && [ "$(grep -c '^fr/g' "$d/fr/g-frames.txt")" -eq 40 ] ||
        { cat "$d/fr/g-frames.txt"; return 1; }
    rm -f "$d"/rep.*
    # the first scan's frames made older than the mark: newer ones are the second's
    touch -d '2001-01-01 00:00' "$d"/fr/g*.png; touch -d '2002-01-01 00:00' "$d/mark"
    sed 's/^40$/5000/' "$d/a.in" > "$d/b.in"
    (cd "$d" && exec "$BIN" --cornea-scan -i b.in b.rec > b.out 2> b.err) & p=$!
    i=0; while ! grep -q '^Frames: ' "$d/b.out" 2>/dev/null && [ $i -lt 400 ]; do sleep 0.05; i=$((i+1)); done
    i=0; while ! ls "$d/fr" | grep -q 'part' && [ $i -lt 400 ]; do sleep 0.02; i=$((i+1)); done
    sleep 0.2
    alive=0; kill -0 $p 2>/dev/null && alive=1
    kill -TERM $p 2>/dev/null; wait $p; rc=$?
    [ "$alive" = 1 ] || { echo "the scan's first lines appeared only at its end"; return 1; }
    [ "$rc" -eq 143 ] || { echo "exit $rc"; cat "$d/b.err"; return 1; }
    grep -q 'lensmat: Interrupted (signal 15) during ' "$d/b.err" &&
        grep -q '^Interrupted (signal 15) during .* frames saved' "$d/b.rec" || { cat "$d/b.err"; return 1; }
    [ ! -e "$d/rep.txt" ] && [ ! -e "$d/rep.csv" ] || { echo "a report was written"; return 1; }
    m=$d/fr/g-frames.txt
    grep -q '^scan interrupted (signal 15) during ' "$m" || { head -5 "$m"; return 1; }
    k=$(grep -c '^fr/g' "$m")
    grep -q "^frames $k of 5000$" "$m" || { head -5 "$m"; return 1; }
    for f in $(grep '^fr/g' "$m"); do
        [ "$d/$f" -nt "$d/mark" ] || { echo "$f is listed but is the first scan's"; return 1; }
    done
    # every frame the second scan wrote is listed; the first scan's others are not
    new=$(cd "$d" && find fr -name 'g[0-9]*.png' -newer mark | sort)
    [ "$new" = "$(grep '^fr/g' "$m" | sort)" ] || { echo "the list is not the scan's frames"; return 1; }
}
check "outputs: an interrupted scan over an earlier scan's frames: its manifest, where it stopped, no report" scan_int

# A long scan shows how far it is on a terminal (stderr only when it is one).
scan_progress() {
    d=$OW/progress; mkdir -p "$d"
    printf 'biconic\n-\nspiral\n60\n12\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n1\n14\n1\n0\n-\n' > "$d/p.in"
    (cd "$d" && "$BIN" --cornea-scan -i p.in f.rec > f.out 2> f.err) || return 1
    ! grep -q 'measuring' "$d/f.err" || { echo "progress on a stderr that is a file"; return 1; }
    python3 - "$BIN" "$d" <<'PYEOF' || return 1
import os, pty, subprocess, sys
m, s = pty.openpty()
p = subprocess.Popen([sys.argv[1], "--cornea-scan", "-i", "p.in", "t.rec"], cwd=sys.argv[2],
                     stdout=open(os.path.join(sys.argv[2], "t.out"), "w"), stderr=s)
os.close(s)
buf = b""
while True:
    try: chunk = os.read(m, 4096)
    except OSError: break
    if not chunk: break
    buf += chunk
p.wait()
ok = p.returncode == 0 and b"lensmat: measuring: point " in buf
print("exit %d, terminal saw %r" % (p.returncode, buf[:200]))
sys.exit(0 if ok else 1)
PYEOF
    cmp "$d/f.rec" "$d/t.rec" || { echo "the record differs with a terminal"; return 1; }
}
check "outputs: a scan's progress on a terminal's stderr only, the record unchanged" scan_progress

# The many-eyes study's tables (scripts/cornea-study.sh) by the same rules: a link to
# its table stays and its target gets the table; a FIFO there carries it.
study_outputs() {
    d=$OW/study; mkdir -p "$d/st"
    ln -s ../keep.tsv "$d/st/study.tsv"; mkfifo "$d/st/percentiles.tsv"
    timeout 120 cat "$d/st/percentiles.tsv" > "$d/pct.got" & cpid=$!
    timeout 120 "$TOP/scripts/cornea-study.sh" -M 2 -p 100 -s 8 -o "$d/st" > "$d/log" 2>&1; rc=$?
    release "$d/st" percentiles.tsv; wait $cpid
    [ "$rc" -eq 0 ] || { echo "exit $rc"; tail -5 "$d/log"; return 1; }
    [ -L "$d/st/study.tsv" ] && [ -p "$d/st/percentiles.tsv" ] || { ls -l "$d/st"; return 1; }
    [ "$(head -c 9 "$d/keep.tsv")" = "$(printf 'eye\ttrue_')" ] && [ "$(wc -l < "$d/keep.tsv")" -eq 3 ] &&
        head -n 1 "$d/pct.got" | grep -q '^parameter' && [ -z "$(ls "$d/st" | grep part)" ]
}
if command -v parallel > /dev/null 2>&1 && parallel --version 2>/dev/null | grep -q 'GNU parallel'; then
    check "outputs: cornea-study.sh's tables through a link and into a FIFO" study_outputs
fi
