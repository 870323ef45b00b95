# t_71_hits.sh -- the hit writer at speed (src/trace/scene_dtoa.cpp, scene_outq.c,
# scene_out.c; issue 23): Dragonbox's digits checked against Python's repr (David Gay's
# dtoa: an independent shortest-digits algorithm) and double-conversion on special
# values, the layout's edges, 200 000 random bit patterns and 200 000 short decimals;
# a trace with many hits (tens of chunks, formatted by 1, 2 and 5 threads that finish
# out of order) writes the same bytes whatever the thread count, every number reads
# back to the bits of the "%.17g" CSV (csv17) and of the .npy; a write error (the
# device is full) stops the trace with a message instead of hanging the writers.

cd "$TOP" || return 1
HT=$WORK/hits
mkdir -p "$HT"
HTPY=
for p in python3 /usr/bin/python3; do
    "$p" -c 'import numpy' 2>/dev/null && { HTPY=$p; break; }
done

# the digits: every string reads back to its double, equals repr's value as a decimal
# (the same shortest digits), has repr's digit count, is laid out %g-like (exponent
# form outside 1e-4 .. 1e17), and double-conversion says the same
ht_digits() {
    b=$1
    [ -x "$b" ] || { echo "$b not built"; return 1; }
    [ -n "$HTPY" ] || { echo "no python3 with numpy"; return 1; }
    # zeros, infinities, nan, the smallest and largest subnormals and normals, the
    # layout's edges (1e-5, 1e-4, 1e16, 1e17 and their neighbours), 2^53, integers
    "$HTPY" -c '
import struct
v = [0.0, -0.0, float("inf"), -float("inf"), float("nan"), 5e-324, -5e-324,
     2.225073858507201e-308, 2.2250738585072014e-308, 1.7976931348623157e308,
     1e-5, 9.999999999999999e-5, 1e-4, 1.0000000000000001e-4, 0.00012345, 1e16,
     9999999999999998.0, 1e17, 99999999999999990.0, 1.0000000000000002e17, 2.0**53,
     2.0**53 + 2, 1.0, 0.1, 0.5, 100.0, 123456789.0, 1e22, 1e23, 1.5e300, 1e-300, 1/3.0]
v += [-x for x in v]
for x in v: print(struct.pack(">d", x).hex())' > "$HT/special"
    "$b" 200000 12345 < "$HT/special" > "$HT/digits" || return 1
    "$HTPY" - "$HT/digits" <<'EOF'
import math, struct, sys
from decimal import Decimal
n = bad = 0
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) != 3:
        sys.exit("bad line: " + line)
    u, s, dc = f
    x = struct.unpack(">d", bytes.fromhex(u))[0]
    n += 1
    why = None
    if s != dc:
        why = "double-conversion says " + dc
    elif math.isnan(x):
        why = None if s == "nan" else "nan"
    elif math.isinf(x):
        why = None if s == ("-inf" if x < 0 else "inf") else "inf"
    elif struct.pack(">d", float(s)) != struct.pack(">d", x):
        why = "reads back to %r" % float(s)
    elif x != 0 and Decimal(s) != Decimal(repr(x)):
        why = "repr gives " + repr(x)
    elif x == 0 and s != ("-0" if math.copysign(1, x) < 0 else "0"):
        why = "zero"
    else:
        e = Decimal(repr(abs(x))).adjusted() if x else 0
        if ("e" in s) != (e < -4 or e >= 17) or s.lstrip("-").startswith("0") and x and "." not in s:
            why = "layout (exponent %d)" % e
    if why:
        bad += 1
        if bad <= 10: print(u, s, why)
if bad or n < 400000:
    sys.exit("%d of %d numbers wrong" % (bad, n))
EOF
}
check "hits: Dragonbox digits = repr's shortest, read back, double-conversion (400 000 doubles)" \
    ht_digits build/obj/trace_tests/dtoa_check
check "hits: the same digits under ASan/UBSan" ht_digits build/asan/trace_tests/dtoa_check

# a lens of two surfaces with Fresnel on, a 300 x 300 grid: 70 688 hits, 17 chunks
ht_scenes() {
    for t in 1 2 5; do
        wd=$HT/t$t; mkdir -p "$wd"
        { echo "cap refract 1 1.5 vertex 0 0 0 radius 30 aperture 8"
          echo "cap refract 1.5 1 vertex 0 0 4 radius -40 aperture 8"
          echo "plane detect at 0 0 40 normal 0 0 1 disc 60"
          echo "source collimated from 0 0 -5 dir 0.01 0.02 1 radius 7 grid 300"
          echo "reflections off"; echo "threads $t"
          echo "output hits h.csv"
          [ "$t" = 1 ] && echo "output segments s.npy"
          : ; } > "$wd/s.scene"
        trace_session "$1" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    done
    wd=$HT/t17; mkdir -p "$wd"
    sed -e 's/^output hits h.csv$/output hits h17.csv csv17/' -e '/^output segments/d' \
        "$HT/t1/s.scene" > "$wd/s.scene"
    trace_session "$1" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    wd=$HT/tn; mkdir -p "$wd"
    sed -e 's/^output hits h.csv$/output hits h.npy/' -e '/^output segments/d' \
        "$HT/t1/s.scene" > "$wd/s.scene"
    trace_session "$1" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    cmp "$HT/t1/h.csv" "$HT/t2/h.csv" && cmp "$HT/t1/h.csv" "$HT/t5/h.csv"
}
check "hits: 70 688 hits as CSV on 1, 2 and 5 threads: the same bytes" ht_scenes "$BIN"

ht_values() {
    [ -n "$HTPY" ] || { echo "no python3 with numpy"; return 1; }
    "$HTPY" - "$HT" <<'EOF'
import struct, sys, numpy
from decimal import Decimal
d = sys.argv[1]
a = open(d + "/t1/h.csv").read().splitlines()
b = open(d + "/t17/h17.csv").read().splitlines()
h = numpy.load(d + "/tn/h.npy")
assert a[0] == b[0] and tuple(a[0].split(",")) == h.dtype.names, (a[0], h.dtype.names)
assert len(a) == len(b) == len(h) + 1 and len(h) == 70688, (len(a), len(b), len(h))
names = a[0].split(",")
bad = 0
for i, (la, lb) in enumerate(zip(a[1:], b[1:])):
    fa, fb = la.split(","), lb.split(",")
    for j, (x, y) in enumerate(zip(fa, fb)):
        if j < 4:
            ok = x == y and int(x) == int(h[i][j])
        else:
            v = float(y)
            ok = (struct.pack("<d", float(x)) == struct.pack("<d", v) ==
                  struct.pack("<d", float(h[i][j])) and Decimal(x) == Decimal(repr(v)))
        if not ok:
            bad += 1
            if bad < 10: print("row", i, names[j], x, y, h[i][j])
sys.exit(1 if bad else 0)
EOF
}
check "hits: every CSV number reads back to the csv17 and .npy bits, as short as repr" ht_values

# a full device: the writers stop, the trace says why and fails (no hang, no file)
ht_full() {
    [ -w /dev/full ] || { echo "no /dev/full (skipped)"; return 0; }
    wd=$HT/full; mkdir -p "$wd"
    sed -e 's|^output hits h.csv$|output hits /dev/full|' -e '/^output segments/d' \
        "$HT/t1/s.scene" > "$wd/s.scene"
    if trace_session "$1" "$wd" scene s.scene n; then echo "the trace did not fail"; return 1; fi
    grep -q 'could not be written\|write error\|No space' "$wd/err" || { cat "$wd/err"; return 1; }
}
check "hits: a CSV to a full device fails with a message" ht_full "$BIN"
check "hits: the same under ASan/UBSan" ht_full "$ASAN"
ht_asan() {
    wd=$HT/asan; mkdir -p "$wd"
    sed -e 's/^threads 1$/threads 3/' "$HT/t1/s.scene" > "$wd/s.scene"
    trace_session "$ASAN" "$wd" scene s.scene n || { cat "$wd/err"; return 1; }
    cmp "$HT/t1/h.csv" "$wd/h.csv"
}
check "hits: 3 formatter threads under ASan/UBSan: the same bytes" ht_asan
