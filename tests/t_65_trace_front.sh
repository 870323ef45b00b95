# t_65_trace_front.sh -- the ray tracer's user side: scene/triangle/media/OBJ readers
# (unit test, and every malformed case through the dialogue with FILE:LINE and exit
# 2), the example scenes traced by both builds with their outputs checked (p.l
# segments, hits CSV, summary, energy balance), the --trace dialogue's replay round
# trip, the lens fan against the paraxial image, the tessellation table, a terminal
# session (bad scene re-asked, progress line), that no paraxial session ever loads
# Embree, and a short fuzz run of the readers.

unit "$TOP/build/obj/unit_trace_scene"
unit "$TOP/build/asan/unit_trace_scene"

SCENES=$TOP/scenes
TW=$WORK/trace
mkdir -p "$TW"

# summary_value FILE KEY
summary_value() { awk -v k="$2" '$1 == k { print $2 }' "$1"; }

# The outputs of one traced scene in DIR: no .part left; the p.l file has two x y z
# lines per segment, as many as the summary counts; the hits CSV has its header and
# one 15-field row per hit; the energy balance holds to 1e-9.
check_outputs() {
    dir=$1; seg=$2; hits=$3; sum=$4
    ls "$dir" | grep -q '\.part$' && { echo "a .part file was left"; return 1; }
    if [ -n "$seg" ]; then
        awk 'NF != 3 { bad = 1 } { for (i = 1; i <= NF; i++) if ($i !~ /^-?[0-9.]+(e[-+][0-9]+)?$/) bad = 1 }
             END { exit bad || NR % 2 }' "$dir/$seg" || { echo "$seg: not pairs of x y z lines"; return 1; }
    fi
    if [ -n "$hits" ]; then
        head -1 "$dir/$hits" | grep -qx 'ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,length,opl' ||
            { echo "$hits: header"; return 1; }
        awk -F, 'NR > 1 && NF != 15 { exit 1 }' "$dir/$hits" || { echo "$hits: fields"; return 1; }
    fi
    if [ -n "$sum" ]; then
        [ -n "$seg" ] && [ "$(wc -l < "$dir/$seg")" -ne $((2 * $(summary_value "$dir/$sum" segments))) ] &&
            { echo "segments in $seg and $sum differ"; return 1; }
        [ -n "$hits" ] && [ "$(($(wc -l < "$dir/$hits") - 1))" -ne "$(summary_value "$dir/$sum" hits)" ] &&
            { echo "hits in $hits and $sum differ"; return 1; }
        awk '$1 == "balance_error" { b = $2 < 0 ? -$2 : $2; found = 1 }
             END { exit !(found && b <= 1e-9) }' "$dir/$sum" || { echo "energy balance"; return 1; }
    fi
    return 0
}

trace_scene_ok() {
    bin=$1; name=$2; dir=$TW/$3
    rm -rf "$dir"
    trace_session "$bin" "$dir" scene "$SCENES/$name.scene" n || { cat "$dir/err"; return 1; }
    grep -q "^Energy balance error: " "$dir/out" && ! grep -q Warning "$dir/out"
}

scene_opticrt() {
    trace_scene_ok "$1" opticrt "o_$2" && check_outputs "$TW/o_$2" p.l '' opticrt.sum
}
scene_singlet() {
    trace_scene_ok "$BIN" singlet s && check_outputs "$TW/s" '' singlet-hits.csv singlet.sum
}
scene_prism() {
    trace_scene_ok "$BIN" prism p && check_outputs "$TW/p" prism.l prism-hits.csv '' &&
        grep -q 'total internal reflections: [1-9]' "$TW/p/out"
}
scene_periscope() {
    trace_scene_ok "$ASAN" periscope g && check_outputs "$TW/g" '' periscope-hits.csv '' &&
        grep -q 'absorbed 0\.0[0-9]*[1-9]' "$TW/g/out"
}
if [ -f "$TOP/build/lib/lensmat-trace.so" ] && [ -f "$TOP/build/asan/lib/lensmat-trace.so" ]; then
    check "trace opt: opticrt scene (sphercap.t, media file), p.l and summary" scene_opticrt "$BIN" opt
    check "trace asan: opticrt scene (sphercap.t, media file), p.l and summary" scene_opticrt "$ASAN" asan
    check "trace: singlet scene, hits CSV matches the summary" scene_singlet
    check "trace: OBJ prism reports total internal reflection" scene_prism
    check "trace asan: Gaussian beam, mirrors, annular stop absorbs" scene_periscope
else
    fail "trace module not built (build/lib/lensmat-trace.so, build/asan/lib/lensmat-trace.so)"
fi

# Results must not depend on the thread count: 1 and 2 threads, same bytes.
threads_same() {
    for t in 1 2; do
        mkdir -p "$TW/th$t"
        sed -e "s/^output hits .*/output hits h.csv/" -e "s/^output summary .*/output summary s.txt/" \
            "$SCENES/singlet.scene" > "$TW/th$t/a.scene"
        echo "threads $t" >> "$TW/th$t/a.scene"
        echo "output segments p.l" >> "$TW/th$t/a.scene"
        trace_session "$BIN" "$TW/th$t" scene a.scene n || return 1
    done
    for f in h.csv s.txt p.l; do cmp "$TW/th1/$f" "$TW/th2/$f" || return 1; done
    [ "$(wc -l < "$TW/th1/h.csv")" -gt 100 ]
}
check "trace: hits, segments and summary identical on 1 and 2 threads" threads_same

# ---- malformed input: clear message with file and line, exit 2, answer not echoed --

# bad_case NAME MESSAGE: scene $TW/bad/NAME.scene (with its files) must be refused
bad_case() {
    d=$TW/bad
    (cd "$d" && printf 'scene\n%s.scene\n' "$1" > "$1.in" &&
        "$BIN" --trace -i "$1.in" "$1.rec" > /dev/null 2> "$1.err")
    rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc, not 2"; cat "$d/$1.err"; return 1; }
    grep -qF "$2" "$d/$1.err" || { echo "message: want '$2'"; cat "$d/$1.err"; return 1; }
    grep -qF "$1.in:2: the scene file: " "$d/$1.err" || { echo "answer line missing"; cat "$d/$1.err"; return 1; }
    ! grep -q "input: $1.scene" "$d/$1.rec" || { echo "rejected answer echoed"; return 1; }
}
mkdir -p "$TW/bad"
SRC='source ray from 0 0 -5 dir 0 0 1'
DET='plane detect at 0 0 10 normal 0 0 1 disc 5'
mk() { f=$TW/bad/$1; shift; printf '%s\n' "$@" > "$f"; }
mk good.t '0 0 0' '1 0 0' '0 1 0' '0 0 1' '1 0 1' '0 1 1'
mk count.t '0 0 0' '1 0' '0 1 0'
mk count.scene 'mesh absorb file count.t' "$SRC"
mk nan.t '0 0 0' '1 0 0' '0 nan 0'
mk nan.scene 'mesh absorb file nan.t' "$SRC"
mk degen.t '0 0 0' '1 0 0' '0 1 0' '2 2 2' '2 2 2' '2 2 2'
mk degen.scene 'mesh absorb file degen.t' "$SRC"
mk zero.t '0 0 0' '1 1 1' '2 2 2'
mk zero.scene 'mesh absorb file zero.t' "$SRC"
mk short.n '1 1.5'
mk short.scene 'mesh media short.n file good.t' "$SRC"
mk long.n '1 1.5' '1 1.5' '1.5 1'
mk long.scene 'mesh media long.n file good.t' "$SRC"
mk neg.n '1 1.5' '-1.5 1'
mk negmedia.scene 'mesh media neg.n file good.t' "$SRC"
mk negindex.scene 'cap refract 1 -1.5 vertex 0 0 0 radius 20 aperture 5' "$SRC"
mk nodir.scene "$DET" 'source ray from 0 0 -5 dir 0 0 0'
mk conic.scene 'conic refract 1 1.5 vertex 0 0 0 radius 5 conic 3 aperture 3' "$SRC"
mk nanscene.scene 'plane detect at 0 0 NaN normal 0 0 1 disc 5' "$SRC"
mk numbers.scene 'plane detect at 0 0 normal 0 0 1 disc 5' "$SRC"
mk bad.obj 'v 0 0 0' 'v 1 0 0' 'f 1 2 3'
mk obj.scene 'mesh absorb file bad.obj' "$SRC"
mk nofile.scene 'mesh absorb file missing.t' "$SRC"
mk unknown.scene "$DET" 'lens 1 2 3' "$SRC"
check "bad: wrong count of numbers" bad_case count "count.scene:1: count.t:2: expected 3 numbers (a vertex: x y z), found 2"
check "bad: NaN in a triangle file" bad_case nan "nan.t:3: a vertex: x y z: 'nan': NaN is not a number"
check "bad: degenerate triangle" bad_case degen "degen.t:4: triangle 2 (lines 4-6) is degenerate"
check "bad: zero-area triangle" bad_case zero "zero.t:1: triangle 1 (lines 1-3) has zero area"
check "bad: media file too short" bad_case short "short.n:1: 1 media lines for 2 triangles"
check "bad: media file too long" bad_case long "long.n:3: more media lines than the mesh has triangles (2)"
check "bad: negative index in a media file" bad_case negmedia "neg.n:2: index of refraction n1 = -1.5 must be positive"
check "bad: negative index in a scene" bad_case negindex "negindex.scene:1: cap: refract 1 -1.5: an index of refraction must be positive"
check "bad: zero-direction ray" bad_case nodir "nodir.scene:2: source ray: 'dir' 0 0 0 is a zero-length direction"
check "bad: conic with no real surface at the aperture" bad_case conic "conic.scene:1: conic: radius 5, conic 3: no real surface at the aperture 3"
check "bad: NaN in a scene" bad_case nanscene "nanscene.scene:1: plane: 'at': 'NaN': NaN is not a number"
check "bad: too few numbers in a scene" bad_case numbers "numbers.scene:1: plane: 'at' needs 3 numbers, found 2"
check "bad: OBJ face with a missing vertex" bad_case obj "bad.obj:3: face: vertex 3 does not exist"
check "bad: missing mesh file" bad_case nofile "nofile.scene:1: missing.t: cannot open"
check "bad: unknown directive" bad_case unknown "unknown.scene:2: unknown directive 'lens'"

# An output that cannot be written: the trace is refused, nothing claims success.
mk noout.scene "$DET" "$SRC" "output segments $TW/no/such/dir/p.l"
check "bad: unwritable output stops with exit 2" sh -c "cd '$TW/bad' &&
    printf 'scene\nnoout.scene\n' | '$BIN' --trace noout.rec > noout.out 2> noout.err;
    [ \$? -eq 2 ] && grep -q 'p.l: cannot write' noout.err && ! grep -q '^Written' noout.out"

# ---- replay round trips: record -> grep input: -> replay -> identical record --------
# (timings go to stdout only, so records compare byte for byte)
replay_trace() {
    bin=$1; shift; d=$TW/rep; rm -rf "$d"; mkdir -p "$d"; cd "$d" || return 1
    if [ "$1" = --example ]; then "$bin" --trace --example a.rec > a.out 2> a.err || return 1
    else printf '%s\n' "$@" > in; "$bin" --trace -i in a.rec > a.out 2> a.err || return 1; fi
    grep input: a.rec > in2
    "$bin" --trace b.rec < in2 > b.out 2> b.err || return 1
    cd "$TOP" || return 1
    cmp "$d/a.rec" "$d/b.rec" || return 1
    sed 's/^input: //' "$d/in2" > "$d/ans"   # --example shows its answers; a replay does not
    for f in a b; do grep -v -e '^Build ' -e '^Output was written' -e '^mesh\|^analytic' \
        "$d/$f.out" | grep -vxFf "$d/ans" > "$d/$f.cmp"; done
    cmp "$d/a.cmp" "$d/b.cmp"
}
check "trace replay: embedded example (lens fans)" replay_trace "$BIN" --example
check "trace replay asan: embedded example" replay_trace "$ASAN" --example
check "trace replay: scene file session" replay_trace "$BIN" scene "$SCENES/prism.scene" y \
    scene "$SCENES/singlet.scene" n
check "trace replay: tessellation table" replay_trace "$BIN" table 20 -30 5 1.6 8 15 n
check "trace replay: bad answers in the first run are not recorded" sh -c "
    cd '$TW' && printf 'scene\n$TW/bad/nodir.scene\n' > x.in &&
    '$BIN' --trace -i x.in x.rec > /dev/null 2>&1; [ \$? -eq 2 ] && ! grep -q nodir x.rec"

# ---- the lens dialogue: near-axis rays agree with the paraxial image --------------
near_axis() {
    d=$TW/lens; rm -rf "$d"; mkdir -p "$d"
    (cd "$d" && "$1" --trace --example e.rec > e.out) || return 1
    cnt=$(grep -c 'meets the paraxial image to' "$d/e.rec")
    [ "$cnt" -eq 2 ] || { echo "$cnt agreement lines"; return 1; }
    sed -n 's/.*meets the paraxial image to \([^ ]*\) relative.*/\1/p' "$d/e.rec" |
        awk '{ if (!($1 < 1e-9)) bad = 1 } END { exit bad }'
}
check "lens fan: near-axis real trace meets the paraxial image to 1e-9" near_axis "$BIN"
check "lens fan: spherical aberration is negative and grows with height" sh -c "
    awk '/^Longitudinal/ { on = 1; next } on && /^  [0-9]/ && \$2 ~ /^[0-9]/ {
            if (\$3 > prev) bad = 1; prev = \$3 }
         /^Near the axis/ { on = 0; prev = 0 } END { exit bad }' '$TW/lens/e.rec' &&
    grep -q '^  10\.8  .*-3\.74' '$TW/lens/e.rec'"

# A lens of 11 surfaces under ASan (the paraxial system keeps long lenses on the heap):
# traced, and nothing leaks.
long_lens() {
    d=$TW/long; rm -rf "$d"; mkdir -p "$d"
    { printf 'lens\n1\n'; i=1
      while [ $i -le 10 ]; do printf '100\n%d\n1.5\n10\ny\n' $((2 * i)); i=$((i + 1)); done
      printf -- '-100\n22\n1\n10\nn\ninf\n0.5\nn\nn\n'; } > "$d/in"
    (cd "$d" && "$ASAN" --trace -i in r.rec > out 2> err) || { cat "$d/err"; return 1; }
    [ ! -s "$d/err" ] && grep -q 'meets the paraxial image' "$d/r.rec"
}
check "lens fan asan: 11 surfaces, no leak" long_lens

# ---- the tessellation table: errors shrink with tessellation, refinement is exact ----
tess_table() {
    d=$TW/tess; rm -rf "$d"
    trace_session "$BIN" "$d" table 50 -50 8 1.5168 12 41 n || { cat "$d/err"; return 1; }
    awk '/^mesh [0-9]+ +[0-9]/ { m[++n] = $4 }
         /\+refine/ { if (!($5 < 1e-9)) bad = 1 }
         /\+normal/ { nm[++k] = $5 }
         END { if (n < 4 || bad) exit 1
               for (i = 2; i <= n; i++) if (!(m[i] < m[i - 1])) exit 1
               for (i = 1; i <= k; i++) if (!(nm[i] < m[i])) exit 1 }' "$d/r.rec" ||
        { cat "$d/r.rec"; return 1; }
}
check "tessellation table: mesh error falls with level; normals help; refinement < 1e-9" tess_table

# ---- a paraxial session never loads Embree; lensmat does not link it -----------------
no_embree() {
    d=$TW/ld; rm -rf "$d"; mkdir -p "$d"; cd "$d" || return 1
    ldd "$BIN" | grep -qi embree && { echo "lensmat links embree"; return 1; }
    ldd "$TOP/build/lib/lensmat-trace.so" | grep -qi embree || { echo "control: module without embree?"; return 1; }
    LD_DEBUG=libs "$BIN" --classic --example c.rec > /dev/null 2> c.ld || return 1
    grep -qi embree c.ld && { echo "classic loaded embree"; return 1; }
    grep -q 'calling init' c.ld || { echo "LD_DEBUG gave nothing"; return 1; }
    # the paraxial half of a --trace session (surfaces entered, no trace yet)
    printf 'lens\n1\n50\n0\n1.5\n10\nn\n' > p.in
    LD_DEBUG=libs "$BIN" --trace -i p.in p.rec > /dev/null 2> p.ld
    grep -qi embree p.ld && { echo "trace dialogue loaded embree before tracing"; return 1; }
    # control: tracing does load it
    LD_DEBUG=libs "$BIN" --trace --example t.rec > /dev/null 2> t.ld || return 1
    grep -qi 'libembree' t.ld || { echo "control: the trace did not load embree"; return 1; }
    cd "$TOP"
}
check "no Embree in lensmat's links or in a paraxial session (LD_DEBUG=libs)" no_embree

# ---- on a terminal: a bad scene file is explained and asked again; progress -------
tty_trace() {
    python3 - "$BIN" "$TW/tty" "$TW/bad" "$SCENES" "$TOP/tests" <<'EOF'
import os, sys
bin_, d, bad, scenes = sys.argv[1:5]
sys.path.insert(0, sys.argv[5])
from ptydrive import drive
os.makedirs(d, exist_ok=True)
big = os.path.join(d, "big.scene")
with open(big, "w") as f:   # 15 M rays: about 4 s by the BVH on 2 threads here
    f.write("cap refract 1 1.5 vertex 0 0 0 radius 50 aperture 12\n"
            "cap refract 1.5 1 vertex 0 0 8 radius -50 aperture 12\n"
            "plane detect at 0 0 55 normal 0 0 1 disc 30\nreflections off\n"
            "source collimated from 0 0 -10 dir 0 0 1 radius 10 grid 4400\n")
def run(keys, timeout=120):
    rc, out = drive([bin_, "--trace", "t.rec"], keys, cwd=d, home=d, timeout=timeout)
    return out, rc
fails = []
out, rc = run([b"scene\n", (bad + "/nodir.scene\n").encode(), (scenes + "/opticrt.scene\n").encode(), b"n\n"])
if rc != 0: fails.append("re-ask session exit %d" % rc)
if "zero-length direction; please answer again" not in out: fails.append("no re-ask message")
if "lensmat: traced" in out: fails.append("progress shown for a short trace")
rec = open(os.path.join(d, "t.rec")).read()
if "nodir" in rec or "input: " + scenes + "/opticrt.scene" not in rec: fails.append("record")
os.environ["LENSMAT_TRACE_BVH"] = "1"   # the BVH: the lens path would end in 0.7 s
out, rc = run([b"scene\n", (big + "\n").encode(), b"n\n"])
if rc != 0: fails.append("big trace exit %d" % rc)
if "lensmat: traced " not in out or "(100%)" not in out: fails.append("no progress line on a long trace")
print("\n".join(fails) or "ok", out[-600:] if fails else "")
sys.exit(1 if fails else 0)
EOF
}
if command -v python3 > /dev/null; then
    check "tty: a bad scene file is explained and asked again; long traces show progress" tty_trace
fi

# ---- fuzz the readers (short; `make fuzz` runs long) -------------------------------
fuzz_trace_short() {
    mkdir -p "$WORK/fuzz-trace"
    "$TOP/build/fuzz_trace_scene" -max_total_time="${FUZZ_SHORT_SECONDS:-15}" -timeout=5 \
        "$WORK/fuzz-trace" "$TOP/tests/fuzz-trace" > "$WORK/fuzz-trace.log" 2>&1 ||
        { tail -30 "$WORK/fuzz-trace.log"; return 1; }
}
if [ -x "$TOP/build/fuzz_trace_scene" ]; then
    check "fuzz: trace scene, triangle, media and OBJ readers (short run)" fuzz_trace_short
else
    fail "build/fuzz_trace_scene not built"
fi

# ---- wrong lenses refused at their question (issue 8) --------------------------------
# lens_refused ANSWERS MESSAGE: a replay stops with MESSAGE (exit 2) and the refused
# answer is not recorded (the last answer given is the refused one).
lens_refused() {
    d=$TW/refuse; rm -rf "$d"; mkdir -p "$d"
    printf "$1" > "$d/in"
    (cd "$d" && "$BIN" --trace -i in r.rec > out 2> err); rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; cat "$d/err"; return 1; }
    grep -qF "$2" "$d/err" || { echo "want: $2"; cat "$d/err"; return 1; }
    n=$(grep -c '^input: ' "$d/r.rec"); want=$(($(printf "$1" | wc -l) - 1))
    [ "$n" -eq "$want" ] || { echo "$n answers recorded, want $want"; return 1; }
}
check "lens: both surfaces at z = 0 refused at the location" lens_refused \
    'lens\n1\n50\n0\n1.5\n12\ny\n-50\n0\n' \
    "in:9: the location of the lens surface: '0': surface 2 would touch surface 1 on the axis and cross it (edge thickness -2.92271 at height 12)"
check "lens: crossing surfaces refused at the semi-diameter" lens_refused \
    'lens\n1\n50\n0\n1.5\n12\ny\n-50\n1\n1\n12\n' \
    "in:11: the semi-diameter of the lens surface: '12': surfaces 1 and 2 would cross at height 7.05337 (edge thickness -1.92271 at the semi-diameter 12): give at most 7.05337"
check "lens: a semi-diameter beyond |radius| refused at its question" lens_refused \
    'lens\n1\n50\n0\n1.5\n60\n' \
    "in:6: the semi-diameter of the lens surface: '60' is larger than 50, the |radius| of this surface"
check "table: crossing surfaces refused at the semi-diameter" lens_refused \
    'table\n50\n-50\n1\n1.5\n12\n' \
    "in:6: the semi-diameter: '12': surfaces 1 and 2 would cross at height 7.05337"
lens_cross_ok() {   # the same lens with semi-diameter 7 traces
    d=$TW/crossok; rm -rf "$d"
    trace_session "$BIN" "$d" lens 1 50 0 1.5 12 y -50 1 1 7 n inf 1 n n || { cat "$d/err"; return 1; }
    grep -q 'meets the paraxial image' "$d/r.rec"
}
check "lens: the crossing lens with a semi-diameter under the crossing traces" lens_cross_ok

# Fraction 1 is the rim of surface 1: from an object at 200 the edge ray is traced and
# met surface 1 at 12 (the heights were once aimed at the vertex plane: vignetted).
fan_rim() {
    grep -A16 '^Object point on the axis at z= -200' "$TW/lens/e.rec" > "$TW/lens/e200"
    grep -q '^  12  *64\.87' "$TW/lens/e200" || { cat "$TW/lens/e200"; return 1; }
    ! grep -q vignetted "$TW/lens/e200"
}
check "lens fan: fraction 1 reaches the rim of surface 1 from a near object" fan_rim

# ---- stopping: SIGTERM / SIGINT mid-trace (issue 8) ----------------------------------
# A 4.5 M-ray scene writing hits: the signal is sent once the hits file has grown; the
# trace must end within 1 s with 128 + N, its outputs only as .part, the record with
# every answer and the stop said.
trace_stopped() {
    python3 - "$1" "$TW/stop$2" "$2" <<'PYEOF'
import os, signal, subprocess, sys, time
bin_, d, sig = sys.argv[1], sys.argv[2], int(sys.argv[3])
os.makedirs(d, exist_ok=True)
for f in os.listdir(d): os.remove(os.path.join(d, f))
open(os.path.join(d, "big.scene"), "w").write(
    "cap refract 1 1.5 vertex 0 0 0 radius 50 aperture 12\n"
    "cap refract 1.5 1 vertex 0 0 8 radius -50 aperture 12\n"
    "plane detect at 0 0 55 normal 0 0 1 disc 30\n"
    "source collimated from 0 0 -10 dir 0 0 1 radius 10 grid 2400\n"
    "output hits h.csv\noutput summary s.sum\n")
open(os.path.join(d, "in"), "w").write("scene\nbig.scene\nn\n")
p = subprocess.Popen([bin_, "--trace", "-i", "in", "r.rec"], cwd=d,
                     stdout=subprocess.DEVNULL, stderr=open(os.path.join(d, "err"), "w"))
def growing():   # the hits file being written: a unique h.csv.part.XXXXXX (lm_out)
    for f in os.listdir(d):
        if f.startswith("h.csv.part"):
            try:
                if os.path.getsize(os.path.join(d, f)) > 200000: return True
            except OSError: pass
    return False
t_end = time.time() + 60
while time.time() < t_end and p.poll() is None:
    if growing(): break
    time.sleep(0.01)
fails = []
if p.poll() is not None: fails.append("the trace ended before the signal (exit %d)" % p.returncode)
t0 = time.time()
p.send_signal(sig)
try: rc = p.wait(timeout=30)
except subprocess.TimeoutExpired: p.kill(); rc = p.wait(); fails.append("did not stop in 30 s")
dt = time.time() - t0
if dt > 1.0: fails.append("stopped %.2f s after the signal" % dt)
if rc != 128 + sig: fails.append("exit %d, want %d" % (rc, 128 + sig))
names = sorted(os.listdir(d))
if "h.csv" in names or "s.sum" in names: fails.append("an output has its final name: %s" % names)
if "h.csv.part" not in names: fails.append("no .part left: %s" % names)
rec = open(os.path.join(d, "r.rec")).read()
if "input: scene\n" not in rec or "input: big.scene\n" not in rec: fails.append("record lost answers")
if "the trace stopped: interrupted" not in rec: fails.append("record does not say the trace stopped")
print("\n".join(fails) or "ok (stopped %.3f s after the signal)" % dt)
sys.exit(1 if fails else 0)
PYEOF
}
if command -v python3 > /dev/null; then
    check "stop: SIGTERM mid-trace ends within 1 s, exit 143, outputs .part, record intact" trace_stopped "$BIN" 15
    check "stop asan: SIGINT mid-trace ends within 1 s, exit 130" trace_stopped "$ASAN" 2
fi

# ---- caps that cross, media that disagree, outputs over inputs (issue 8) -------------
CAP1='cap refract 1 1.5168 vertex 0 0 0 radius 50 aperture 12'
mk crosscap.scene "$CAP1" 'cap refract 1.5168 1 vertex 0 0 1 radius -50 aperture 12' "$DET" "$SRC"
mk touchcap.scene 'cap refract 1.5168 1 vertex 0 0 0 axis 0 0 -1 radius 50 aperture 12' \
    'cap refract 1 1.5168 vertex 0 0 0 axis 0 0 -1 radius -50 aperture 12' "$DET" "$SRC"
mk outscene.scene "$DET" "$SRC" 'output hits outscene.scene'
mk outmesh.scene 'mesh absorb file good.t' "$SRC" 'output segments good.t'
mk g.n.part '1 1.5' '1 1.5'
mk outmedia.scene 'mesh media g.n.part file good.t' "$SRC" 'output summary g.n'
mk outtwice.scene "$DET" "$SRC" 'output hits same.txt' 'output summary same.txt'
mk outrec.scene "$DET" "$SRC" 'output summary outrec.rec'
mk outin.scene "$DET" "$SRC" 'output segments outin.in'
mk mmbad.scene 'mismatch maybe' "$DET" "$SRC"
check "bad: caps whose sags cross within the apertures" bad_case crosscap \
    "crosscap.scene:1: and crosscap.scene:2: the surfaces cross at height 7.05337 from their axis (edge thickness -1.92271 at 12): negative edge thickness"
check "bad: caps on a reversed axis touching at the vertex and crossing" bad_case touchcap \
    "touchcap.scene:1: and touchcap.scene:2: the surfaces cross at height 0 from their axis"
check "bad: an output over the scene file" bad_case outscene \
    "outscene.scene: output hits outscene.scene would overwrite the scene file outscene.scene"
check "bad: an output over a mesh file" bad_case outmesh \
    "output segments good.t would overwrite the mesh file good.t"
check "bad: an output's .part over a media file" bad_case outmedia \
    "output summary g.n would overwrite the media file g.n.part"
check "bad: two outputs in one file" bad_case outtwice \
    "output summary same.txt would overwrite output same.txt"
check "bad: an output over the record" bad_case outrec "outrec.scene: output outrec.rec: "
check "bad: an output over the answers" bad_case outin "outin.scene: output outin.in: "
check "bad: mismatch takes warn or error" bad_case mmbad "mmbad.scene:1: mismatch: expected warn or error"
good_t_intact() { [ "$(wc -l < "$TW/bad/good.t")" -eq 6 ] && [ ! -e "$TW/bad/good.t.part" ]; }
check "bad: the refused outputs left the inputs as they were" good_t_intact

# A cap declared 'refract 1.6 1' after '1 1.5168': said after the trace with the
# surfaces' lines and the count; 'mismatch error' makes it an error (outputs .part).
MM2='cap refract 1.6 1 vertex 0 0 8 radius -50 aperture 12'
MMDET='plane detect at 0 0 55 normal 0 0 1 disc 30'
MMSRC='source collimated from 0 0 -10 dir 0 0 1 radius 10 grid 21'
mismatch_warn() {
    d=$TW/mm; rm -rf "$d"; mkdir -p "$d"
    printf '%s\n' "$CAP1" "$MM2" "$MMDET" "$MMSRC" > "$d/mm.scene"
    trace_session "$BIN" "$d" scene mm.scene n || { cat "$d/err"; return 1; }
    grep -q '^Warning: [1-9][0-9]* rays met a surface whose index' "$d/r.rec" &&
    grep -q "the first: mm.scene:1: gives 1.5168 after it, mm.scene:2: expects 1.6 before it" "$d/r.rec" &&
    grep -q 'mismatch error' "$d/out" || { cat "$d/out"; return 1; }
}
check "mismatch: media that disagree are said on screen with file:line and the count" mismatch_warn
mismatch_error() {
    d=$TW/mm; printf '%s\n' 'mismatch error' 'output hits h.csv' >> "$d/mm.scene"
    (cd "$d" && printf 'scene\nmm.scene\nn\n' | "$BIN" --trace e.rec > e.out 2> e.err); rc=$?
    [ "$rc" -eq 2 ] && [ ! -e "$d/h.csv" ] && [ -e "$d/h.csv.part" ] &&
    grep -q "rays met a surface .*first mm.scene:1: .*(the scene says .mismatch error.)" "$d/e.err" ||
        { echo "exit $rc"; cat "$d/e.err"; return 1; }
}
check "mismatch error: the trace fails, outputs left as .part" mismatch_error
consistent_quiet() {   # the consistent singlet says nothing of media
    trace_session "$BIN" "$TW/mmok" scene "$SCENES/singlet.scene" n &&
        ! grep -qi 'media\|mismatch' "$TW/mmok/out"
}
check "mismatch: a consistent scene says nothing about media" consistent_quiet

# The tessellation table stops on a signal too (its traces poll the stop flag per
# batch of 4096 rays): a 1001 x 1001 bundle takes many seconds; SIGTERM after 0.5 s.
table_stopped() {
    d=$WORK/tablestop; rm -rf "$d"; mkdir -p "$d"
    printf 'table\n50\n-50\n8\n1.5168\n12\n1001\nn\n' > "$d/in"
    python3 - "$1" "$d" <<'PYEOF'
import os, signal, subprocess, sys, time
bin_, d = sys.argv[1], sys.argv[2]
p = subprocess.Popen([bin_, "--trace", "-i", "in", "r.rec"], cwd=d,
                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
time.sleep(0.5)
fails = []
if p.poll() is not None: fails.append("the table ended before the signal (exit %d)" % p.returncode)
t0 = time.time()
p.send_signal(signal.SIGTERM)
try: rc = p.wait(timeout=30)
except subprocess.TimeoutExpired: p.kill(); rc = p.wait(); fails.append("did not stop in 30 s")
dt = time.time() - t0
if dt > 1.0: fails.append("stopped %.2f s after the signal" % dt)
if rc != 143: fails.append("exit %d, want 143" % rc)
rec = open(os.path.join(d, "r.rec")).read()
if "input: 1001\n" not in rec: fails.append("record lost answers")
print("\n".join(fails) or "ok (%.3f s)" % dt)
sys.exit(1 if fails else 0)
PYEOF
}
if command -v python3 > /dev/null; then
    check "stop: SIGTERM during the tessellation table ends within 1 s, exit 143, record intact" \
        table_stopped "$BIN"
fi

# An index may be a medium's or a glass's name in --trace too (issue 8): echoed as the
# name, and the replay of the grep'd record gives the same record.
trace_index_name() {
    d=$WORK/tindex; rm -rf "$d"
    trace_session "$BIN" "$d" lens 1 50 0 N-BK7 12 y -50 5 water 12 n 200 1 n n || return 1
    grep -q '^input: water$' "$d/r.rec" && grep -q '^(water: index 1.333)$' "$d/r.rec" &&
    grep -qi '^input: n-bk7' "$d/r.rec" &&
    (cd "$d" && grep input: r.rec > again && "$BIN" --trace -i again r2.rec > /dev/null) &&
    cmp "$d/r.rec" "$d/r2.rec"
}
check "lens: an index given as a medium or glass name (water, N-BK7), exact replay" trace_index_name
