# t_68_scene_packet.sh -- a sequential lens found inside a scene file (tr_seqscan.c)
# takes the lens shortcut and the packets, and changes no bit: every scene here is
# traced twice through lensmat --trace, as it is and with LENSMAT_TRACE_BVH=1 (every
# segment through Embree), and the segments, hits and summary files and the record
# must be the same bytes.  Scenes: the Cooke triplet (also listed backwards, and on two
# threads), a singlet, a conic singlet, a lens with meshes before and after it and one
# beside it, a concave mirror behind a lens, a 45-degree fold mirror, a tilted and a
# decentred lens and an aspheric one (no lens found), sources from the far side and
# from inside the lens; Fresnel and reflections on and off.  The screen says how many
# surfaces took the lens path; that number is checked too.  The engine's own test of
# the same (scenes built through the table, hints made stale by later surfaces) is
# tests/trace/t_seqscan.c.

# the engine's side, through its table (tests/trace/t_seqscan.c)
unit "$TOP/build/obj/trace_tests/t_seqscan"
unit "$TOP/build/asan/trace_tests/t_seqscan"

PK=$WORK/scenepkt
mkdir -p "$PK"

# The Cooke triplet of tests/trace/tt.h (vertices from its thicknesses, mounts as
# absorbing annuli at each rim) with a detector at its paraxial image.
pk_triplet() {
    awk 'BEGIN { split("22.01359 -435.76044 -22.21328 20.29192 79.68360 -18.39533", R, " ")
                 split("3.25896 6.00764 0.99963 4.75041 2.95208 42.20778", T, " ")
                 split("1.62041 1.0 1.62004 1.0 1.62041 1.0", N, " ")
                 split("8.0 8.0 5.5 5.5 7.5 7.5", SD, " ")
                 n = 1; z = 0
                 for (i = 1; i <= 6; i++) {
                     c = 1 / R[i]; s = SD[i]; sag = c * s * s / (1 + sqrt(1 - c * c * s * s))
                     printf "cap refract %s %s vertex 0 0 %.17g radius %s aperture %s\n", n, N[i], z, R[i], SD[i]
                     printf "plane absorb at 0 0 %.17g normal 0 0 1 disc 40 hole %s\n", z + sag, SD[i]
                     n = N[i]; z += T[i]
                 }
                 print "plane detect at 0 0 60.404971618172183 normal 0 0 1 disc 50" }'
}

pk_singlet() {
    cat <<'EOF'
cap refract 1 1.5168 vertex 0 0 0 radius 50 aperture 12
cap refract 1.5168 1 vertex 0 0 8 radius -50 aperture 12
EOF
}

# pk_outputs: every output the comparison reads
pk_outputs() {
    printf 'output segments segs.l\noutput hits hits.csv\noutput summary sum.txt\n'
}

# pk_same NAME SCENE LENS: trace SCENE (a file under $PK) both ways; the outputs and the
# record must be byte for byte the same, and the screen must say that LENS surfaces
# took the lens path (0: no lens found, no such line).
pk_same() {
    name=$1; scene=$2; lens=$3; d=$PK/$name
    rm -rf "$d"
    trace_session "${PKBIN:-$BIN}" "$d/pk" scene "$scene" n || { echo "packet run failed"; cat "$d/pk/err"; return 1; }
    LENSMAT_TRACE_BVH=1 trace_session "${PKBIN:-$BIN}" "$d/bvh" scene "$scene" n ||
        { echo "BVH run failed"; cat "$d/bvh/err"; return 1; }
    for f in segs.l hits.csv sum.txt r.rec; do
        [ -s "$d/pk/$f" ] || { echo "$f: not written"; return 1; }
        cmp "$d/pk/$f" "$d/bvh/$f" || { echo "$f differs between the lens path and the BVH"; return 1; }
    done
    grep -q '^Sequential lens' "$d/bvh/out" && { echo "LENSMAT_TRACE_BVH=1 still took the lens path"; return 1; }
    got=$(sed -n 's/^Sequential lens: \([0-9]*\) surfaces.*/\1/p' "$d/pk/out")
    [ "${got:-0}" -eq "$lens" ] || { echo "lens path: $got surfaces, expected $lens"; return 1; }
    # the trace did something worth comparing
    awk '$1 == "rays" && $2 > 0 { r = 1 } END { exit !r }' "$d/pk/sum.txt" ||
        { echo "no rays traced"; return 1; }
    return 0
}

# pk_modes NAME LENS BODY-FILE: the scene with Fresnel and reflections on and off
pk_modes() {
    name=$1; lens=$2; body=$3
    for fr in on off; do
        for rf in on off; do
            s=$PK/$name-$fr-$rf.scene
            { cat "$body"; echo "fresnel $fr"; echo "reflections $rf"; pk_outputs; } > "$s"
            pk_same "$name-$fr-$rf" "$s" "$lens" || { echo "(fresnel $fr, reflections $rf)"; return 1; }
        done
    done
}

# -- the scenes' bodies --
{ pk_triplet; echo "source collimated from 0 0 -5 dir 0 0 1 radius 7.9 grid 41"; } > "$PK/triplet.body"
# the same surfaces listed backwards (ids against z), on two threads, with a point source
{ pk_triplet | awk '{ l[NR] = $0 } END { for (i = NR; i > 0; i--) print l[i] }'
  echo "source point from 0 0 -300 toward 0 0 0 radius 7 rings 12"; echo "threads 2"; } > "$PK/triplet_rev.body"
# a meniscus (its faces overlap in z: one slab of two) before a singlet; with mounts
# the meniscus's slab holds four and the singlet is left to Embree
cat > "$PK/meniscus.body" <<'EOF'
cap refract 1 1.6 vertex 0 0 0 radius 20 aperture 10
cap refract 1.6 1 vertex 0 0 1.5 radius 25 aperture 10
cap refract 1 1.5168 vertex 0 0 8 radius 50 aperture 12
cap refract 1.5168 1 vertex 0 0 16 radius -50 aperture 12
plane detect at 0 0 45 normal 0 0 1 disc 40
source collimated from 0 0 -5 dir 0 0 1 radius 11 grid 31
EOF
{ cat "$PK/meniscus.body"
  echo "plane absorb at 0 0 2.679491924311227 normal 0 0 1 disc 30 hole 10"
  echo "plane absorb at 0 0 3.5871215252208 normal 0 0 1 disc 30 hole 10"; } > "$PK/meniscus_mounts.body"
# glasses at three wavelengths (one run each); an absorbing glass (N-BK7 at 334 nm:
# Beer-Lambert, traced ray by ray, the lens shortcut still choosing the surfaces)
cat > "$PK/wl.body" <<'EOF'
cap refract 1 N-SF6 vertex 0 0 0 radius 50 aperture 12
cap refract N-SF6 1 vertex 0 0 8 radius -50 aperture 12
plane detect at 0 0 55 normal 0 0 1 disc 40
source collimated from 0 0 -10 dir 0 0 1 radius 11.9 grid 21 lambda F d C
EOF
sed -e 's/N-SF6/N-BK7/g' -e 's/lambda F d C/lambda 334/' "$PK/wl.body" > "$PK/absorbing.body"
# a mesh vane across the beam between the first and second elements: the lens path
# starts after it (surfaces 3 to 6, their mounts and the detector)
{ pk_triplet; echo "plane absorb at 0 3 6 normal 0 0 1 rect 20 2 tessellate 2"
  echo "source collimated from 0 0 -5 dir 0 0 1 radius 7.9 grid 41"; } > "$PK/vane.body"
{ pk_singlet; echo "plane detect at 0 0 55.0190998600405 normal 0 0 1 disc 30"
  echo "source collimated from 0 0 -10 dir 0 0 1 radius 11.9 grid 31"
  echo "source fan from 0 -5 -40 dir 0 0.1 1 angle 12 rays 41"; } > "$PK/singlet.body"
cat > "$PK/conic.body" <<'EOF'
conic refract 1 1.5 vertex 0 0 0 radius 40 conic -0.6 aperture 12
cap refract 1.5 1 vertex 0 0 7 radius -60 aperture 12
plane detect at 0 0 60 normal 0 0 1 disc 40
source collimated from 0 0 -3 dir 0 0 1 radius 12 grid 25
EOF
# meshes: a tessellated glass plate before the lens (a source left of it, one between
# it and the lens), a tessellated detector after it
{ pk_singlet
  echo "plane refract 1 1.5 at 0 0 -8 normal 0 0 1 disc 16 tessellate 3"
  echo "plane refract 1.5 1 at 0 0 -6 normal 0 0 1 disc 16 tessellate 3"
  echo "plane detect at 0 0 55 normal 0 0 1 disc 30 tessellate 4"
  echo "source collimated from 0 0 -20 dir 0 0 1 radius 11 grid 21"
  echo "source collimated from 0 0 -3 dir 0 0 1 radius 11 grid 21"; } > "$PK/mesh.body"
# a mesh ball beside the lens, within its z range, and a bubble in its glass: no lens
{ pk_singlet; echo "sphere refract 1 1.5 center 30 0 4 radius 5 tessellate 4"
  echo "sphere refract 1.5168 1 center 4 0 4 radius 1.5 tessellate 5"
  echo "plane detect at 0 0 55 normal 0 0 1 disc 60"
  echo "source collimated from 0 0 -10 dir 0 0.3 1 radius 12 grid 21"; } > "$PK/beside.body"
# a concave mirror on the axis behind the lens sends the light back through it to a
# detector behind the source
{ pk_singlet; echo "cap mirror vertex 0 0 80 radius -80 aperture 20"
  echo "plane detect at 0 0 -30 normal 0 0 1 disc 40"
  echo "source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21"; } > "$PK/mirror.body"
# a fold mirror at 45 degrees after the lens, detector above it
{ pk_singlet; echo "plane mirror at 0 0 30 normal 0 1 -1 rect 30 30"
  echo "plane detect at 0 30 30 normal 0 1 0 rect 30 30 up 0 0 1"
  echo "source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21"; } > "$PK/fold.body"
# a tilted lens, a decentred one and an aspheric one: no sequential lens
cat > "$PK/tilted.body" <<'EOF'
cap refract 1 1.5168 vertex 0 0 0 axis 0 0.1 1 radius 50 aperture 12
cap refract 1.5168 1 vertex 0 0.8 8 axis 0 0.1 1 radius -50 aperture 12
plane detect at 0 0 55 normal 0 0 1 disc 40
source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21
EOF
cat > "$PK/decentred.body" <<'EOF'
cap refract 1 1.5168 vertex 0 0 0 radius 50 aperture 12
cap refract 1.5168 1 vertex 0.5 0 8 radius -50 aperture 12
plane detect at 0 0 55 normal 0 0 1 disc 40
source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21
EOF
cat > "$PK/asphere.body" <<'EOF'
asphere refract 1 1.5168 vertex 0 0 0 radius 50 conic 0 coef 0 1e-6 aperture 12
cap refract 1.5168 1 vertex 0 0 8 radius -50 aperture 12
plane detect at 0 0 55 normal 0 0 1 disc 40
source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21
EOF
# sources from both sides, detectors on both; and rays starting inside the lens
{ pk_singlet; echo "plane detect at 0 0 -30 normal 0 0 1 disc 40"
  echo "plane detect at 0 0 60 normal 0 0 1 disc 40"
  echo "source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 21"
  echo "source collimated from 0 0 50 dir 0 0 -1 radius 11 grid 21"
  echo "source cone from 0 0 40 dir 0 0 -1 angle 10 rings 6"; } > "$PK/farside.body"
{ pk_singlet; echo "plane detect at 0 0 55 normal 0 0 1 disc 40"
  echo "source fan from 0 0 4 dir 0 0 1 angle 20 rays 31 medium 1.5168"
  echo "source fan from 0 0 7.5 dir 0 0 1 angle 20 rays 31 medium 1.5168"
  echo "source collimated from 0 0 -10 dir 0 0 1 radius 11 grid 11"; } > "$PK/inside.body"

if [ -f "$TOP/build/lib/lensmat-trace.so" ]; then
    check "scene lens path: Cooke triplet, 13 surfaces, same bits as the BVH (Fresnel, reflections on/off)" \
        pk_modes triplet 13 "$PK/triplet.body"
    check "scene lens path: the triplet listed backwards, 2 threads, point source" \
        pk_modes triplet_rev 13 "$PK/triplet_rev.body"
    check "scene lens path: a mesh vane between two elements of the triplet" \
        pk_modes vane 9 "$PK/vane.body"
    check "scene lens path: a meniscus (faces overlapping in z) and a singlet" \
        pk_modes meniscus 5 "$PK/meniscus.body"
    check "scene lens path: the same with the meniscus mounted: the meniscus alone" \
        pk_modes meniscus_mounts 4 "$PK/meniscus_mounts.body"
    check "scene lens path: glasses at F, d and C" pk_modes wl 3 "$PK/wl.body"
    check "scene lens path: an absorbing glass (ray by ray, the shortcut on)" \
        pk_modes absorbing 3 "$PK/absorbing.body"
    check "scene lens path: singlet, collimated and tilted fan" pk_modes singlet 3 "$PK/singlet.body"
    check "scene lens path: conic singlet" pk_modes conic 3 "$PK/conic.body"
    check "scene lens path: meshes before and after the lens (rays from either side of the plate)" \
        pk_modes mesh 2 "$PK/mesh.body"
    check "scene lens path: a mesh beside the lens in its z range: no lens" pk_modes beside 0 "$PK/beside.body"
    check "scene lens path: concave mirror behind the lens" pk_modes mirror 3 "$PK/mirror.body"
    check "scene lens path: 45-degree fold mirror after the lens" pk_modes fold 2 "$PK/fold.body"
    check "scene lens path: tilted lens: none" pk_modes tilted 0 "$PK/tilted.body"
    check "scene lens path: decentred lens: none" pk_modes decentred 0 "$PK/decentred.body"
    check "scene lens path: aspheric surface: none" pk_modes asphere 0 "$PK/asphere.body"
    check "scene lens path: sources from the far side" pk_modes farside 3 "$PK/farside.body"
    check "scene lens path: rays starting inside the lens" pk_modes inside 3 "$PK/inside.body"
fi
# the example scenes: every output they name the same both ways
pk_examples() {
    for e in singlet opticrt periscope prism; do
        d=$PK/ex_$e
        rm -rf "$d"
        trace_session "$BIN" "$d/pk" scene "$TOP/scenes/$e.scene" n || { cat "$d/pk/err"; return 1; }
        LENSMAT_TRACE_BVH=1 trace_session "$BIN" "$d/bvh" scene "$TOP/scenes/$e.scene" n ||
            { cat "$d/bvh/err"; return 1; }
        for f in $(ls "$d/pk"); do
            case $f in in|out|err) continue ;; esac
            cmp "$d/pk/$f" "$d/bvh/$f" || { echo "$e: $f differs"; return 1; }
        done
    done
    grep -q '^Sequential lens: 3 surfaces' "$PK/ex_singlet/pk/out" || { echo "singlet: no lens found"; return 1; }
}
if [ -f "$TOP/build/lib/lensmat-trace.so" ]; then
    check "scene lens path: the example scenes, every output the same both ways" pk_examples
fi
# the screen names the packet kernel that ran: LENSMAT_ISA's choice, the same bits
pk_kernel() {
    d=$PK/kernel; rm -rf "$d"
    LENSMAT_ISA=sse2 trace_session "$BIN" "$d/sse2" scene "$TOP/scenes/singlet.scene" n || return 1
    LENSMAT_ISA=scalar trace_session "$BIN" "$d/scalar" scene "$TOP/scenes/singlet.scene" n || return 1
    grep -q '^Sequential lens: 3 surfaces traced on the lens path (kernel sse2;' "$d/sse2/out" ||
        { grep '^Sequential' "$d/sse2/out"; return 1; }
    grep -q '(kernel scalar;' "$d/scalar/out" || { grep '^Sequential' "$d/scalar/out"; return 1; }
    cmp "$d/sse2/r.rec" "$d/scalar/r.rec"
}
if [ -f "$TOP/build/lib/lensmat-trace.so" ] && grep -qw sse2 /proc/cpuinfo 2>/dev/null; then
    check "scene lens path: the screen names the kernel LENSMAT_ISA chose" pk_kernel
fi
if [ -f "$TOP/build/asan/lib/lensmat-trace.so" ]; then
    pk_asan() {
        { cat "$PK/mesh.body"; pk_outputs; } > "$PK/asan.scene"
        PKBIN=$ASAN; pk_same asan "$PK/asan.scene" 2; rc=$?; PKBIN=; return $rc
    }
    check "scene lens path asan: meshes before and after the lens" pk_asan
fi
