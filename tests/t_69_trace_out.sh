# t_69_trace_out.sh -- the tracer's record outputs (src/trace/scene_out.c, issue 23):
# hits as CSV with the shortest numbers that read back to the same doubles, as NumPy
# .npy and as HDF5 (one file with /hits, /segments, /summary).  Every file is read
# back by other programs (Python's float(), NumPy, h5py) and compared against the
# CSV of before (keyword csv17: "%.17g", which reads back exactly): every double must
# come back to the bit.  The CSV's numbers must also be the shortest that do (as
# short as Python's repr, an independent shortest-digits algorithm).  The example
# scene's csv17 output must be the bytes the tracer wrote before this format existed
# (golden/trace/scenes.sha256 holds the sums of both).

cd "$TOP" || return 1
# the engine's batch sink, which the writers take the records from, against the
# one-by-one sink: the same bytes (tests/trace/t_batch.c)
unit "$TOP/build/obj/trace_tests/t_batch"
unit "$TOP/build/asan/trace_tests/t_batch"
TO=$WORK/traceout
mkdir -p "$TO"
# a Python with NumPy and h5py (a pyenv shim may hide the system's)
TOPY=
for p in python3 /usr/bin/python3; do
    "$p" -c 'import numpy, h5py' 2>/dev/null && { TOPY=$p; break; }
done

# to_trace NAME SCENE-FILE...: copy the example scenes to $TO/NAME, trace SCENE there
to_trace() {
    wd=$TO/$1; rm -rf "$wd"; mkdir -p "$wd"
    cp "$TOP"/scenes/* "$wd/"
    trace_session "$BIN" "$wd" scene "$2" n || { cat "$wd/err"; return 1; }
}

# The prism scene (TIR, 291 hits, 1649 segments) four ways: csv17, CSV, .npy, HDF5 (all)
to_scenes() {
    s=$TOP/scenes/prism.scene
    grep -v '^output' "$s" > "$TO/base"
    { cat "$TO/base"; echo "output hits h17.csv csv17"; echo "output segments s.l"
      echo "output summary s.sum"; } > "$TO/p17.scene"
    { cat "$TO/base"; echo "output hits h.csv"; } > "$TO/pcsv.scene"
    { cat "$TO/base"; echo "output hits h.npy"; echo "output segments s.npy"; } > "$TO/pnpy.scene"
    { cat "$TO/base"; echo "output all all.h5"; } > "$TO/ph5.scene"
    # a scene that names wavelengths: the lambda_nm column
    { echo "plane refract 1 N-BK7 at 0 0 0 normal 0 0 1 disc 8"
      echo "plane refract N-BK7 1 at 0 0 10 normal 0 -0.5 0.8660254037844386 disc 8"
      echo "plane detect at 0 0 60 normal 0 0 1 rect 400 400"
      echo "source collimated from 0 0 -5 dir 0 0 1 radius 2 grid 5 lambda F d C"
      echo "reflections off" ; } > "$TO/wbase"
    { cat "$TO/wbase"; echo "output hits w17.csv csv17"; } > "$TO/w17.scene"
    { cat "$TO/wbase"; echo "output hits w.csv"; echo "output segments ws.l"; } > "$TO/wcsv.scene"
    { cat "$TO/wbase"; echo "output hits w.npy"; echo "output segments ws.npy"; } > "$TO/wnpy.scene"
    { cat "$TO/wbase"; echo "output all w.hdf5"; } > "$TO/wh5.scene"
    for sn in p17 pcsv pnpy ph5 w17 wcsv wnpy wh5; do
        mkdir -p "$TO/$sn"; cp "$TOP"/scenes/prism.obj "$TO/$sn/"; mv "$TO/$sn.scene" "$TO/$sn/s.scene"
        trace_session "$BIN" "$TO/$sn" scene s.scene n || { echo "$sn:"; cat "$TO/$sn/err"; return 1; }
    done
}
check "trace out: the prism and a three-wavelength prism traced with csv17, CSV, .npy and HDF5 outputs" to_scenes

# CSV: the same doubles as csv17, to the bit, and the shortest digits
to_csv() {
    "${TOPY:-python3}" - "$TO/p17/h17.csv" "$TO/pcsv/h.csv" "$TO/w17/w17.csv" "$TO/wcsv/w.csv" <<'EOF'
import sys, struct
def bits(x): return struct.pack('<d', x)
def digits(s):   # significant digits of a decimal string
    m = s.lower().split('e')[0].lstrip('-').replace('.', '').lstrip('0').rstrip('0')
    return len(m) or 1
for ref, new in ((sys.argv[1], sys.argv[2]), (sys.argv[3], sys.argv[4])):
    a = open(ref).read().splitlines(); b = open(new).read().splitlines()
    assert a[0] == b[0], "header differs: %r %r" % (a[0], b[0])
    assert len(a) == len(b) and len(a) > 10, "rows: %d %d" % (len(a), len(b))
    n = shorter = 0
    for x, y in zip(a[1:], b[1:]):
        xs, ys = x.split(','), y.split(',')
        assert len(xs) == len(ys)
        for i, (u, v) in enumerate(zip(xs, ys)):
            if i < 4: assert u == v, (u, v); continue     # integers: the same text
            assert bits(float(u)) == bits(float(v)), "%s reads back as %r, not %r" % (v, float(v), float(u))
            if a[0].endswith('lambda_nm') and i == len(xs) - 1: continue  # %.10g, as before
            r = repr(float(v))
            assert digits(v) == digits(r), "%s: %d digits, repr %s has %d" % (v, digits(v), r, digits(r))
            shorter += len(v) < len(u); n += 1
    print("%s: %d values read back to the bit, %d shorter than %%.17g; %d vs %d bytes" %
          (new, n, shorter, len(open(new).read()), len(open(ref).read())))
    assert shorter > 0 and len(open(new).read()) < len(open(ref).read())
EOF
}
check "trace out: CSV hits are the csv17 doubles to the bit, in the fewest digits (Python float and repr)" to_csv

# .npy: NumPy reads the CSV's columns with their names, the same doubles and integers
to_npy() {
    [ -n "$TOPY" ] || { echo "no python3 with numpy and h5py"; return 1; }
    "$TOPY" - "$TO" <<'EOF'
import sys, struct, numpy as np
d = sys.argv[1]
def rows(path):
    t = open(path).read().splitlines()
    return t[0].split(','), [r.split(',') for r in t[1:]]
for csv, npy in (("p17/h17.csv", "pnpy/h.npy"), ("w17/w17.csv", "wnpy/w.npy")):
    head, r = rows(d + "/" + csv)
    a = np.load(d + "/" + npy)
    assert list(a.dtype.names) == head, (a.dtype.names, head)
    assert a.shape == (len(r),), (a.shape, len(r))
    for j, name in enumerate(head):
        col = a[name]
        if j < 4:
            assert [int(x[j]) for x in r] == col.tolist(), name
        else:
            want = np.array([float(x[j]) for x in r])
            assert col.dtype == np.float64 and (col.view(np.uint64) == want.view(np.uint64)).all(), name
    print("%s: %d rows x %d columns, every value the csv17 one" % (npy, len(r), len(head)))
# segments: the p.l text's points ("%.10g") within its rounding, in order
def pl(path, k):
    v = [list(map(float, l.split())) for l in open(path) if l.strip()]
    return np.array([a[:3] + b[:3] + a[3:] for a, b in zip(v[0::2], v[1::2])])
for text, npy, k in (("p17/s.l", "pnpy/s.npy", 6), ("wcsv/ws.l", "wnpy/ws.npy", 7)):
    want = pl(d + "/" + text, k)
    a = np.load(d + "/" + npy)
    got = np.stack([a[n] for n in a.dtype.names], axis=1)
    assert got.shape == want.shape, (got.shape, want.shape)
    err = np.abs(got - want) / np.maximum(np.abs(want), 1e-300)
    assert ((np.abs(got - want) <= 1e-12) | (err <= 5.1e-10)).all(), err.max()
    print("%s: %d segments, within %%.10g of %s" % (npy, len(a), text))
EOF
}
check "trace out: .npy hits and segments read by NumPy: the CSV's columns, every double exact" to_npy

# HDF5: h5py reads /hits and /segments (the .npy tables, bit for bit) and /summary
# (the text summary's numbers)
to_h5() {
    [ -n "$TOPY" ] || { echo "no python3 with numpy and h5py"; return 1; }
    "$TOPY" - "$TO" <<'EOF'
import sys, numpy as np, h5py
d = sys.argv[1]
for h5, hn, sn in (("ph5/all.h5", "pnpy/h.npy", "pnpy/s.npy"), ("wh5/w.hdf5", "wnpy/w.npy", "wnpy/ws.npy")):
    f = h5py.File(d + "/" + h5, "r")
    assert sorted(f.keys()) == ["hits", "segments", "summary"], list(f.keys())
    for name, npy in (("hits", hn), ("segments", sn)):
        a, b = np.load(d + "/" + npy), f[name][()]
        assert a.dtype.names == b.dtype.names and a.shape == b.shape, name
        for c in a.dtype.names:
            assert (a[c] == b[c]).all() and a[c].tobytes() == b[c].tobytes(), (name, c)
    print("%s: /hits %d rows, /segments %d rows, as the .npy files" % (h5, len(f["hits"]), len(f["segments"])))
# /summary against the csv17 run's text summary
s = {}
for line in open(d + "/p17/s.sum"):
    k, v = line.split()[:2]
    s[k] = v
at = h5py.File(d + "/ph5/all.h5", "r")["summary"].attrs
assert at["scene"] == "s.scene", at["scene"]
for k, v in s.items():
    if k == "scene": continue
    if k == "balance_error": assert abs(float(at[k]) - float(v)) <= 1e-3 * abs(float(v)) + 1e-300; continue
    assert k in at, k
    assert (int(v) == int(at[k])) if "." not in v and "e" not in v else float(v) == float(at[k]), (k, v, at[k])
print("/summary: %d values as the text summary" % (len(s) - 1))
w = h5py.File(d + "/wh5/w.hdf5", "r")["summary/wavelengths"][()]
assert sorted(w["wavelength_nm"].tolist()) == [486.1327, 587.5618, 656.2725], w["wavelength_nm"]
assert w["rays"].sum() == h5py.File(d + "/wh5/w.hdf5", "r")["summary"].attrs["rays"]
print("/summary/wavelengths:", w["wavelength_nm"].tolist())
EOF
}
check "trace out: one HDF5 file (output all) read by h5py: /hits, /segments as the .npy, /summary as the text" to_h5

# HDF5 outputs in files of their own: hits in one, segments and summary in another
to_h5_apart() {
    [ -n "$TOPY" ] || { echo "no python3 with numpy and h5py"; return 1; }
    wd=$TO/h5apart; rm -rf "$wd"; mkdir -p "$wd"; cp "$TOP"/scenes/prism.obj "$wd/"
    { cat "$TO/base"; echo "output hits h.h5"; echo "output segments ss.hdf5"
      echo "output summary ss.hdf5"; } > "$wd/s.scene"
    trace_session "$BIN" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    "$TOPY" - "$wd" "$TO/pnpy" <<'EOF2'
import sys, numpy as np, h5py
d, n = sys.argv[1], sys.argv[2]
h, s = h5py.File(d + "/h.h5", "r"), h5py.File(d + "/ss.hdf5", "r")
assert list(h.keys()) == ["hits"] and sorted(s.keys()) == ["segments", "summary"], (list(h.keys()), list(s.keys()))
assert h["hits"][()].tobytes() == np.load(n + "/h.npy").tobytes()
assert s["segments"][()].tobytes() == np.load(n + "/s.npy").tobytes()
assert s["summary"].attrs["hits"] == len(h["hits"])
print("h.h5: /hits; ss.hdf5: /segments, /summary; the .npy bytes")
EOF2
}
check "trace out: HDF5 tables in files of their own (hits apart, segments with the summary)" to_h5_apart

# the keyword wins over the name; unknown keywords and `all` to a non-HDF5 file refused
to_bad() {
    wd=$TO/bad; rm -rf "$wd"; mkdir -p "$wd"
    printf '%s\n' "plane detect at 0 0 5 normal 0 0 1 disc 5" "source ray from 0 0 0 dir 0 0 1" \
        "output hits h.dat npy" > "$wd/s.scene"
    trace_session "$BIN" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    "${TOPY:-python3}" -c "import numpy; a = numpy.load('$wd/h.dat'); assert a.shape == (1,) and a['z'][0] == 5" ||
        { echo "h.dat (keyword npy) is not a .npy"; return 1; }
    for bad in "output hits h.csv xls:'xls' is not a format" \
               "output all a.csv:the tables go together in one HDF5 file" \
               "output summary s.npy:output summary: text or h5"; do
        line=${bad%%:*}; msg=${bad#*:}
        printf '%s\n' "plane detect at 0 0 5 normal 0 0 1 disc 5" "source ray from 0 0 0 dir 0 0 1" \
            "$line" > "$wd/s.scene"
        (cd "$wd" && printf 'scene\ns.scene\n' | "$BIN" --trace -i /dev/stdin r2.rec > out 2> err)
        grep -q "s.scene:3: .*$msg" "$wd/out" "$wd/err" ||
            { echo "'$line' not refused with '$msg':"; cat "$wd/out" "$wd/err"; return 1; }
    done
}
check "trace out: a format keyword overrides the name; a bad keyword, 'all' to a CSV, a .npy summary refused" to_bad

# csv17 keeps the bytes of before: the example prism's hits through csv17 against the
# sum recorded by the tracer before this change (golden/trace/old_csv17.sha256)
to_old_bytes() {
    wd=$TO/old; rm -rf "$wd"; mkdir -p "$wd"; cp "$TOP"/scenes/* "$wd/"
    sed 's/^output hits prism-hits.csv$/output hits prism-hits.csv csv17/' "$TOP/scenes/prism.scene" > "$wd/prism.scene"
    trace_session "$BIN" "$wd" scene prism.scene n || { cat "$wd/err"; return 1; }
    want=b188caf8745ab7f236074244561fab21384890bda10d44b3a25efcebc6d1ccad   # before issue 23
    [ "$(sha256sum < "$wd/prism-hits.csv" | cut -d' ' -f1)" = "$want" ] ||
        { echo "csv17 is not the CSV of before"; return 1; }
}
check "trace out: csv17 writes the prism's hits byte for byte as the tracer did before" to_old_bytes

# ---- closed solids of plane faces (issue 18) -------------------------------------
# A right-angle prism of three `plane refract` faces (legs z = 0 and y = 0, 10 mm,
# hypotenuse y + z = 10) and a cube of six: faces that meet along their edges bound a
# solid and are traced; planes that cross inside both apertures are still refused.
# Expected values from the closed forms, computed here with awk.
S2=0.7071067811865476
to_prism() {   # NAME THETA_DEG N: a ray tilted by THETA in the y-z plane onto leg z = 0
    wd=$TO/$1; rm -rf "$wd"; mkdir -p "$wd"
    d=$(awk -v t="$2" 'BEGIN { a = t * atan2(0, -1) / 180; printf "0 %.17g %.17g", sin(a), cos(a) }')
    printf '%s\n' "plane refract 1 $3 at 0 5 0 normal 0 0 1 rect 10 10 up 0 1 0" \
        "plane refract $3 1 at 0 0 5 normal 0 -1 0 rect 10 10 up 0 0 1" \
        "plane refract $3 1 at 0 5 5 normal 0 $S2 $S2 rect 10 14.142135623730951 up 0 $S2 -$S2" \
        "plane detect at 0 -20 5 normal 0 -1 0 rect 200 200" \
        "source ray from 0 3 -5 dir $d" "reflections off" \
        "output hits h.csv" "output summary s.sum" > "$wd/p.scene"
    trace_session "$BIN" "$wd" scene p.scene n || { cat "$wd/err"; return 1; }
}
# the tilt at which the ray meets the hypotenuse at the critical angle:
# inside angle t' = 45 deg - asin(1/n), outside asin(n sin t')
prism_crit() { awk -v n="$1" 'BEGIN { pi = atan2(0, -1); c = atan2(1 / n, sqrt(1 - 1 / (n * n)))
    s = n * sin(pi / 4 - c); printf "%.12f\n", atan2(s, sqrt(1 - s * s)) * 180 / pi }'; }
to_tir() {
    for pn in 1.5 1.7; do
        tc=$(prism_crit $pn)
        for dt in -0.05 0.05; do
            t=$(awk -v a="$tc" -v b="$dt" 'BEGIN { printf "%.12f", a + b }')
            to_prism "tir$pn$dt" "$t" "$pn" || return 1
            tir=$(awk '$1 == "tir" { print $2 }' "$TO/tir$pn$dt/s.sum")
            want=$(awk -v d="$dt" 'BEGIN { print (d < 0 ? 1 : 0) }')
            [ "$tir" = "$want" ] || { echo "n $pn, tilt $t (critical $tc): $tir TIR, want $want"; return 1; }
            [ "$want" = 1 ] || continue
            # totally reflected: out along the input mirrored in the hypotenuse,
            # (0, -cos t, -sin t), a deviation of 90 + 2t degrees
            awk -F, -v t="$t" 'NR == 2 { pi = atan2(0, -1); a = t * pi / 180
                e = ($8 - 0) ^ 2 + ($9 + cos(a)) ^ 2 + ($10 + sin(a)) ^ 2
                dev = atan2(sqrt(1 - (sin(a) * $9 + cos(a) * $10) ^ 2), sin(a) * $9 + cos(a) * $10) * 180 / pi
                printf "tilt %.6f deg: deviation %.12f deg (closed form %.12f), direction error %.2g\n", t, dev, 90 + 2 * t, sqrt(e)
                ok = sqrt(e) < 1e-12 && (dev - 90 - 2 * t) ^ 2 < 1e-18 } END { exit !ok }' "$TO/tir$pn$dt/h.csv" || return 1
        done
        echo "n $pn: critical tilt $tc deg: TIR below it, none above"
    done
}
check "trace out: a right-angle prism of three plane faces: TIR on the closed form's side of the critical angle, deviation 90 + 2t" to_tir

to_cube() {
    wd=$TO/cube; rm -rf "$wd"; mkdir -p "$wd"
    printf '%s\n' "plane refract 1 1.5 at 0 0 0 normal 0 0 1 rect 10 10" \
        "plane refract 1.5 1 at 0 0 10 normal 0 0 1 rect 10 10" \
        "plane refract 1 1.5 at -5 0 5 normal 1 0 0 rect 10 10" \
        "plane refract 1.5 1 at 5 0 5 normal 1 0 0 rect 10 10" \
        "plane refract 1 1.5 at 0 -5 5 normal 0 1 0 rect 10 10" \
        "plane refract 1.5 1 at 0 5 5 normal 0 1 0 rect 10 10" \
        "plane detect at 0 0 30 normal 0 0 1 rect 200 200" \
        "source ray from -2 1 -5 dir 0.3 0.2 1" "reflections off" \
        "output hits h.csv" "output summary s.sum" > "$wd/c.scene"
    trace_session "$BIN" "$wd" scene c.scene n || { cat "$wd/err"; return 1; }
    # Snell at z = 0 (tangential components / n), straight to z = 10, out parallel
    awk -F, 'NR == 2 { n = 1.5; l = sqrt(0.09 + 0.04 + 1); dx = 0.3 / l; dy = 0.2 / l; dz = 1 / l
        x1 = -2 + dx * 5 / dz; y1 = 1 + dy * 5 / dz; L1 = 5 / dz
        ex = dx / n; ey = dy / n; ez = sqrt(1 - ex * ex - ey * ey)
        x2 = x1 + ex * 10 / ez; y2 = y1 + ey * 10 / ez; L2 = 10 / ez
        x3 = x2 + dx * 20 / dz; y3 = y2 + dy * 20 / dz; L3 = 20 / dz
        e = ($8 - dx) ^ 2 + ($9 - dy) ^ 2 + ($10 - dz) ^ 2; p = ($5 - x3) ^ 2 + ($6 - y3) ^ 2
        o = $15 - (L1 + n * L2 + L3)
        printf "out (%.17g %.17g %.17g), in (%.17g %.17g %.17g): error %.2g; position error %.2g, opl error %.2g\n", $8, $9, $10, dx, dy, dz, sqrt(e), sqrt(p), o
        ok = sqrt(e) < 1e-12 && sqrt(p) < 1e-9 && o * o < 1e-18 } END { exit !ok }' "$wd/h.csv"
}
check "trace out: a cube of six plane faces: the transmitted ray leaves parallel, displaced and delayed as Snell says" to_cube

to_crossing() {
    wd=$TO/cross; rm -rf "$wd"; mkdir -p "$wd"
    for geo in "at 0 0 5 normal 0 $S2 $S2 rect 10 10:at 0 0 5 normal 0 $S2 -$S2 rect 10 10" \
               "at 0 0 5 normal 0 0 1 disc 5:at 0 0 5 normal 0 1 0 rect 10 10"; do
        printf '%s\n' "plane refract 1 1.5 ${geo%%:*}" "plane refract 1.5 1 ${geo#*:}" \
            "plane detect at 0 0 30 normal 0 0 1 disc 50" "source ray from 0 0 -5 dir 0 0 1" > "$wd/x.scene"
        (cd "$wd" && printf 'scene\nx.scene\n' | "$BIN" --trace -i /dev/stdin r.rec > out 2> err)
        grep -q "x.scene:2: this refracting plane crosses the one of line 1 inside both their apertures" "$wd/out" "$wd/err" ||
            { echo "not refused: ${geo}"; cat "$wd/out" "$wd/err"; return 1; }
    done
}
check "trace out: refracting planes that cross inside both apertures (an X, a disc through a square) are still refused" to_crossing

# ---- meshes: kept as shared vertices, refused before reading when they cannot fit --
# A 300 x 300 quad grid (180 000 triangles, written here with awk) traced from its OBJ
# (shared vertices) and from the same triangles as a triangle file (three vertex lines
# each, the soup the OBJ reader made before): the same bytes out.  Under a 250 MB
# address-space limit it is refused before it is read, with what it needs; with no
# limit it traces.
to_mesh_files() {
    wd=$TO/mesh; rm -rf "$wd"; mkdir -p "$wd"
    awk 'BEGIN { n = 300; for (i = 0; i <= n; i++) for (j = 0; j <= n; j++) printf "v %d %d %g\n", i, j, (i * j) % 7 * 0.01
        for (i = 0; i < n; i++) for (j = 0; j < n; j++) { a = i * (n + 1) + j + 1; b = a + 1; c = a + n + 1; d = c + 1
            printf "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c } }' > "$wd/grid.obj"
    awk '$1 == "v" { v[++n] = $2 " " $3 " " $4 } $1 == "f" { print v[$2]; print v[$3]; print v[$4] }' "$wd/grid.obj" > "$wd/grid.t"
    for m in obj t; do
        printf '%s\n' "mesh refract 1 1.5 file grid.$m" "plane detect at 150 150 30 normal 0 0 1 disc 100" \
            "source collimated from 150 150 -20 dir 0.1 0.05 1 radius 40 grid 30" \
            "output hits h_$m.csv" "output segments s_$m.l" > "$wd/$m.scene"
        trace_session "$BIN" "$wd/$m" scene ../$m.scene n || { cat "$wd/$m/err"; return 1; }
    done
    [ "$(wc -l < "$wd/obj/h_obj.csv")" -gt 100 ] || { echo "too few hits"; return 1; }
    cmp "$wd/obj/h_obj.csv" "$wd/t/h_t.csv" && cmp "$wd/obj/s_obj.l" "$wd/t/s_t.l"
}
check "trace out: an OBJ kept as shared vertices traces to the bytes of its triangle soup (.t)" to_mesh_files

to_mesh_limit() {
    wd=$TO/mesh
    [ -f "$wd/grid.obj" ] || { echo "no grid.obj"; return 1; }
    (cd "$wd" && ulimit -v 250000 && printf 'scene\nobj.scene\n' | "$BIN" --trace -i /dev/stdin r2.rec > lim.out 2> lim.err)
    rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc under ulimit -v 250000"; cat "$wd/lim.out" "$wd/lim.err"; return 1; }
    grep -q "obj.scene:1: .*grid.obj: 180000 triangles need about [0-9]* MB of address space to trace .*more than the [0-9]* MB left under the limit (ulimit -v): not read" "$wd/lim.out" "$wd/lim.err" ||
        { echo "no refusal naming the need:"; cat "$wd/lim.out" "$wd/lim.err"; return 1; }
}
check "trace out: a mesh that cannot fit under the address-space limit is refused before it is read, saying what it needs" to_mesh_limit
