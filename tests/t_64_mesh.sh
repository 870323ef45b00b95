# t_64_mesh.sh -- meshes traced through lensmat --trace after the memory and margin
# work of issue 23 (src/trace/tr_scene.c, tr_hit.c, tr_wt.c):
# - seven mesh scenes (tests/mesh/scenes.sh: a refracting UV-sphere OBJ with a
#   detector, the same on two threads, as a mirror, a TIR prism, an open sheet hit on
#   its vertices, edges and boundary, a tessellated singlet behind an analytic window,
#   the sphere with a detector 4000 away) give the hits lensmat gave before that work
#   (golden/trace/mesh.sha256, written by lensmat at d720c04);
# - the same scenes traced with LENSMAT_TRACE_EXACT=1 (every mesh hit decided by the
#   double-precision test of the triangles around it, no float margin or float
#   distance trusted) give the same bytes: hits, segments, summary;
# - the open sheet: every ray crosses it exactly once (two segments a ray, the first
#   ending at z = 0), counted from the segments file against the beam's own geometry;
# - a mesh that cannot fit under the address-space limit is refused before it is
#   read: the refusal names what it needs, and the same file without the limit is
#   read and refused for the error it holds on its last line (so the first refusal
#   came before the reader); the same against the memory available
#   (LENSMAT_MEMAVAILABLE_KB stands for MemAvailable), its need checked against the
#   bytes a triangle and a vertex it quotes.

cd "$TOP" || return 1
MW=$WORK/mesh64
mkdir -p "$MW"
M64_SCENES="refract mirror tir sheet mix threads far"

# m64_trace BIN OUT [ENV=VALUE]: trace every scene into OUT/NAME
m64_trace() {
    sh "$TOP/tests/mesh/scenes.sh" "$2" || return 1
    for s in $M64_SCENES; do
        mkdir -p "$2/$s"; cp "$2"/*.obj "$2/$s.scene" "$2/$s/"
        for try in 1 2; do
            (cd "$2/$s" && printf 'scene\n%s.scene\nn\n' "$s" |
                env ${3:-LENSMAT_M64=1} "$1" --trace -i /dev/stdin r.rec > out 2> err) && break
            # LeakSanitizer's own tracer thread can crash at exit on this loaded
            # machine ("Tracer caught signal 11", no report of ours): once more
            grep -q "LeakSanitizer has encountered a fatal error" "$2/$s/err" &&
                ! grep -q "ERROR: AddressSanitizer\|runtime error" "$2/$s/err" && [ $try -eq 1 ] && continue
            echo "$s:"; cat "$2/$s/out" "$2/$s/err"; return 1
        done
    done
}

m64_golden() {
    m64_trace "$BIN" "$MW/run" || return 1
    (cd "$MW/run" && grep -v '^#' "$GOLDEN/trace/mesh.sha256" | sha256sum -c --quiet)
}
check "mesh: seven mesh scenes give the hits lensmat gave before (golden/trace/mesh.sha256)" m64_golden

# m64_same DIR: every scene's hits, segments and summary in DIR as in the first run
m64_same() {
    for s in $M64_SCENES; do
        for f in hits.csv seg.l sum; do
            cmp "$MW/run/$s/$f" "$1/$s/$f" || { echo "$s/$f differs"; return 1; }
        done
    done
}

m64_exact() {
    m64_trace "$BIN" "$MW/exact" LENSMAT_TRACE_EXACT=1 && m64_same "$MW/exact"
}
check "mesh: every mesh hit decided in double (LENSMAT_TRACE_EXACT=1) gives the same bytes" m64_exact

# a big mesh goes to Embree in chunks (tr_meshbvh.c: Morton order, a BVH a chunk under
# an instance, each chunk's float triangles unmapped after its build, so a read by
# Embree would fault): the seven scenes in chunks of 7 triangles (the sphere in 332,
# the prism in one) give the golden bytes, and so with every hit decided in double
m64_chunks() {
    m64_trace "$BIN" "$MW/chunk" LENSMAT_TRACE_CHUNK=7 || return 1
    (cd "$MW/chunk" && grep -v '^#' "$GOLDEN/trace/mesh.sha256" | sha256sum -c --quiet) || return 1
    m64_trace "$BIN" "$MW/chunkx" "LENSMAT_TRACE_CHUNK=7 LENSMAT_TRACE_EXACT=1" &&
        m64_same "$MW/chunkx"
}
check "mesh: the seven scenes with their meshes in chunks of 7 triangles give the same bytes" m64_chunks

# under the sanitizers: the open sheet and the prism, as one BVH and in chunks, same hits
m64_asan() {
    [ -x "$ASAN" ] || { echo "no $ASAN"; return 1; }
    keep=$M64_SCENES; M64_SCENES="sheet tir"
    m64_trace "$ASAN" "$MW/asan"; rc=$?
    [ $rc -eq 0 ] && { m64_trace "$ASAN" "$MW/asanc" LENSMAT_TRACE_CHUNK=3; rc=$?; }
    M64_SCENES=$keep
    [ $rc -eq 0 ] || return 1
    for s in sheet tir; do
        for d in asan asanc; do
            grep -q "ERROR: AddressSanitizer\|runtime error" "$MW/$d/$s/err" && { cat "$MW/$d/$s/err"; return 1; }
            cmp "$MW/run/$s/hits.csv" "$MW/$d/$s/hits.csv" || return 1
        done
    done
}
check "mesh: the sheet and the prism under ASan/UBSan, as one BVH and in chunks of 3, the same hits" m64_asan

# the sheet z = 0, |x|, |y| <= 2: each ray of the beam (x, y on the 0.5 grid, within
# 2.25 of the axis) starts at z = -5, meets it once at its own x, y and goes on to the
# detector at z = 10 (index 1 both sides: not deflected)
m64_sheet() {
    awk 'NR % 2 == 1 { x0 = $1; y0 = $2; z0 = $3; next }
         { k = (NR / 2 - 1) % 2; r = int((NR / 2 - 1) / 2)
           if ($1 != x0 || $2 != y0) { print "segment " NR / 2 " deflected"; bad = 1 }
           if (k == 0 && ($3 != 0 || z0 != -5)) { print "ray " r " does not meet the sheet first"; bad = 1 }
           if (k == 1 && (z0 != 0 || $3 != 10)) { print "ray " r " does not go from the sheet to the detector"; bad = 1 }
           if (k == 0 && (x0 * 2 != int(x0 * 2) || y0 * 2 != int(y0 * 2))) { print "ray " r " off the grid"; bad = 1 }
           if (k == 0 && (x0 == 2 || x0 == -2 || y0 == 2 || y0 == -2)) edge++
           n++ }
         END { if (n != 138) { print n " segments, not 2 for each of 69 rays"; bad = 1 }
               if (edge < 4) { print "only " edge " rays on the sheet boundary"; bad = 1 }
               exit bad }' "$MW/run/sheet/seg.l"
}
check "mesh: rays on every vertex, edge and boundary of an open OBJ sheet cross it exactly once" m64_sheet

# 180 000 triangles (a 300 x 300 grid, 31 MB of address space and more for Embree)
# whose last line is not OBJ
m64_limit() {
    wd=$MW/lim; mkdir -p "$wd"
    awk 'BEGIN { n = 301
        for (j = 0; j < n; j++) for (i = 0; i < n; i++) printf "v %d %d 0\n", i, j
        for (j = 0; j < n - 1; j++) for (i = 0; i < n - 1; i++) {
            a = 1 + j * n + i; printf "f %d %d %d\nf %d %d %d\n", a, a + 1, a + n + 1, a, a + n + 1, a + n }
        print "bogus 1 2 3" }' > "$wd/big.obj"
    printf '%s\n' "mesh refract 1 1.5 file big.obj" "plane detect at 0 0 10 normal 0 0 1 disc 500" \
        "source collimated from 150 150 -5 dir 0 0 1 radius 1 grid 3" > "$wd/big.scene"
    (cd "$wd" && ulimit -v 250000 && printf 'scene\nbig.scene\n' | "$BIN" --trace -i /dev/stdin r.rec > lim.out 2>&1)
    rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc under ulimit -v 250000"; cat "$wd/lim.out"; return 1; }
    grep -q "big.obj: 180000 triangles need about [0-9]* MB of address space to trace .*(ulimit -v): not read" "$wd/lim.out" ||
        { echo "no refusal naming the need:"; cat "$wd/lim.out"; return 1; }
    grep -q "bogus" "$wd/lim.out" && { echo "the file was read:"; cat "$wd/lim.out"; return 1; }
    (cd "$wd" && printf 'scene\nbig.scene\n' | "$BIN" --trace -i /dev/stdin r2.rec > free.out 2>&1)
    rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc without the limit"; cat "$wd/free.out"; return 1; }
    grep -q "big.obj:270602: 'bogus': not an OBJ statement" "$wd/free.out" ||
        { echo "without the limit, not the reader's error:"; cat "$wd/free.out"; return 1; }
}
check "mesh: a mesh that cannot fit under ulimit -v is refused before it is read, naming its need" m64_limit

# the same file against the memory available: 20 MB is too little (more than 131 072
# triangles: in chunks, 108 bytes a triangle and 32 a vertex: 180 000 x 108 + 90 601 x
# 32 bytes = 21 MB), 200 MB is not
m64_avail() {
    wd=$MW/lim
    [ -f "$wd/big.obj" ] || { echo "no big.obj"; return 1; }
    (cd "$wd" && printf 'scene\nbig.scene\n' | LENSMAT_MEMAVAILABLE_KB=20000 "$BIN" --trace -i /dev/stdin r3.rec > avail.out 2>&1)
    rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc with 20 MB available"; cat "$wd/avail.out"; return 1; }
    grep -q "big.obj: 180000 triangles need about 21 MB to trace (108 bytes a triangle and 32 a vertex, .*more than the 20 MB of memory available (MemAvailable): not read" "$wd/avail.out" ||
        { echo "no refusal naming the need:"; cat "$wd/avail.out"; return 1; }
    grep -q "bogus" "$wd/avail.out" && { echo "the file was read:"; cat "$wd/avail.out"; return 1; }
    (cd "$wd" && printf 'scene\nbig.scene\n' | LENSMAT_MEMAVAILABLE_KB=200000 "$BIN" --trace -i /dev/stdin r4.rec > avail2.out 2>&1)
    grep -q "big.obj:270602: 'bogus'" "$wd/avail2.out" ||
        { echo "with 200 MB available, not the reader's error:"; cat "$wd/avail2.out"; return 1; }
}
check "mesh: a mesh that cannot fit in the memory available is refused before it is read, naming its need" m64_avail
