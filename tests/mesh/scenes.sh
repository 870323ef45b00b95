#!/bin/sh
# tests/mesh/scenes.sh DIR -- writes the mesh scenes tests/t_64_mesh.sh traces (and
# golden/trace/mesh.sha256 holds the sums of what they gave before the memory and
# margin work of issue 23): a UV sphere OBJ (2 320 triangles, poles fanned) as a
# refracting ball with a detector, as a mirror, a right-angle prism with TIR, an open
# OBJ sheet hit on every vertex and edge, a tessellated singlet behind an analytic
# window (a mix), two threads, and a sphere far from a large detector.
set -e
D=$1
mkdir -p "$D"
python3 - "$D" <<'PY'
import math, sys
d = sys.argv[1]
def sphere(path, nu, nv, r):
    with open(path, "w") as out:
        w = out.write
        w("v 0 0 %.17g\n" % r)
        for i in range(1, nu):
            th = math.pi * i / nu; z = r * math.cos(th); s = r * math.sin(th)
            for j in range(nv):
                w("v %.17g %.17g %.17g\n" % (s * math.cos(2 * math.pi * j / nv),
                                              s * math.sin(2 * math.pi * j / nv), z))
        w("v 0 0 %.17g\n" % -r)
        last = 2 + (nu - 1) * nv
        V = lambda i, j: 2 + (i - 1) * nv + (j % nv)
        for j in range(nv): w("f 1 %d %d\n" % (V(1, j + 1), V(1, j)))
        for i in range(1, nu - 1):
            for j in range(nv):
                w("f %d %d %d\nf %d %d %d\n" % (V(i, j), V(i, j + 1), V(i + 1, j + 1),
                                                V(i, j), V(i + 1, j + 1), V(i + 1, j)))
        for j in range(nv): w("f %d %d %d\n" % (last, V(nu - 1, j), V(nu - 1, j + 1)))
sphere(d + "/ball.obj", 30, 40, 10)
# an open sheet z = 0, x and y from -2 to 2 in steps of 1 (32 triangles)
with open(d + "/sheet.obj", "w") as out:
    for j in range(5):
        for i in range(5): out.write("v %d %d 0\n" % (i - 2, j - 2))
    for j in range(4):
        for i in range(4):
            a = 1 + j * 5 + i
            out.write("f %d %d %d\nf %d %d %d\n" % (a, a + 1, a + 6, a, a + 6, a + 5))
PY
cp scenes/prism.obj "$D/"
O='output hits hits.csv csv17
output segments seg.l
output summary sum'
printf '%s\n' "mesh refract 1 1.5 file ball.obj" \
    "plane detect at 0 0 40 normal 0 0 1 disc 60" \
    "source collimated from 0 0 -20 dir 0 0 1 radius 10.5 grid 41" "$O" > "$D/refract.scene"
printf '%s\n' "mesh mirror file ball.obj" \
    "plane detect at 0 0 -30 normal 0 0 -1 disc 200" \
    "source collimated from 0 0 -20 dir 0 0.1 1 radius 10.5 grid 41" "$O" > "$D/mirror.scene"
printf '%s\n' "mesh refract 1 1.5 file prism.obj" \
    "plane detect at 0 -5 7 normal 0 -1 0 rect 20 20" \
    "source collimated from 0 3 -5 dir 0 0 1 radius 1.5 grid 41" "$O" > "$D/tir.scene"
# the grid's rays at x, y = k/2 (|x|, |y| <= 2) land on every vertex and edge midpoint
# of the sheet inside the beam, some on its boundary; index 1 on both sides
printf '%s\n' "mesh refract 1 1 file sheet.obj" \
    "plane detect at 0 0 10 normal 0 0 1 disc 50" \
    "source collimated from 0 0 -5 dir 0 0 1 radius 2.25 grid 9" "$O" > "$D/sheet.scene"
printf '%s\n' "plane refract 1 1.2 at 0 0 -3 normal 0 0 1 disc 15" \
    "cap refract 1.2 1.5168 vertex 0 0 0 radius 50 aperture 12 tessellate 24" \
    "cap refract 1.5168 1 vertex 0 0 8 radius -50 aperture 12 tessellate 24 refine" \
    "plane detect at 0 0 55 normal 0 0 1 disc 30" \
    "source collimated from 0 0 -10 dir 0 0 1 radius 10 grid 31" "$O" > "$D/mix.scene"
{ sed 's/^output.*//' "$D/refract.scene"; echo "threads 2"; echo "$O"; } > "$D/threads.scene"
printf '%s\n' "mesh refract 1 1.5 file ball.obj" \
    "plane detect at 0 0 4000 normal 0 0 1 disc 3000" \
    "source collimated from 0 0 -20 dir 0.001 0 1 radius 10.5 grid 41" "$O" > "$D/far.scene"
