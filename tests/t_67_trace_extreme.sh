# t_67_trace_extreme.sh -- the tracer at the extremes from scene files (issue 9): every
# case is traced or refused with its cause, never aborted (the engine-side rows with
# their exact figures are tests/trace/t_extreme.c, in t_60_trace.sh).
XW=$WORK/extreme
mkdir -p "$XW"

# xscene NAME LINES...: a scene file NAME.scene in $XW
xscene() { n=$1; shift; printf '%s\n' "$@" > "$XW/$n.scene"; }
# xtrace BIN NAME: trace it in $XW/NAME (exit status of lensmat)
xtrace() {
    rm -rf "$XW/$2"
    trace_session "$1" "$XW/$2" scene "$XW/$2.scene" n
}
# x_traced NAME HITS: exit 0, HITS detector hits, no warning
x_traced() {
    xtrace "$BIN" "$1" || { cat "$XW/$1/err"; return 1; }
    grep -q "^Detector hits: $2 *\$" "$XW/$1/out" || { grep Detector "$XW/$1/out"; return 1; }
    ! grep -q Warning "$XW/$1/out"
}
# x_refused NAME TEXT: exit 2 (not 134: no abort), TEXT in the message
x_refused() {
    xtrace "$BIN" "$1"; rc=$?
    [ "$rc" -eq 2 ] || { echo "exit $rc"; cat "$XW/$1/err"; return 1; }
    grep -q "$2" "$XW/$1/err" || { cat "$XW/$1/err"; return 1; }
}

xscene rect20 'plane detect at 0 0 10 normal 0 0 1 rect 1e20 1e20' \
    'source collimated from 0 0 -10 dir 0 0 1 radius 1 grid 5'
check "extreme: a detector rect 1e20 x 1e20 gets its 21 hits" x_traced rect20 21
xscene sphere19 'sphere detect center 0 0 0 radius 1e19' 'source cone from 0 0 0 dir 0 0 1 angle 30 rings 2'
check "extreme: a detector sphere of radius 1e19 sees its 19 rays" x_traced sphere19 19
xscene far18 'plane detect at 0 0 10 normal 0 0 1 disc 1' 'source ray from 0 0 -1.9e18 dir 0 0 1'
check "extreme: a ray from z = -1.9e18 is traced (no Embree abort)" x_traced far18 1
xscene tinycap 'cap detect vertex 0 0 0 radius 1e-3 aperture 1e-3' \
    'source point from 0 0 -1e6 toward 0 0 0 radius 0.9e-3 rings 6'
check "extreme: a cap of radius 1e-3 seen from 1e6 records all 127 rays" x_traced tinycap 127
xscene glass200 'plane refract 1e-200 1.5 at 0 0 0 normal 0 0 1 disc 1' \
    'plane detect at 0 0 -10 normal 0 0 1 disc 1' 'source ray from 0 0 1 dir 0 0 -1 medium 1.5'
check "extreme: index 1e-200 is refused by the range, not a NaN abort" x_refused glass200 \
    "glass200.scene:1: .*'1e-200' is out of range (0, or 1e-30"
for v in 'radius 5 aperture 1e-200' 'radius 1e-400 aperture 1' 'radius 1e-310 aperture 1'; do
    n=$(echo "$v" | tr -c 'a-z0-9\n' _)
    xscene "$n" "cap detect vertex 0 0 0 $v" 'source ray from 0 0 -1 dir 0 0 1'
    check "extreme: '$v' is refused with the range" x_refused "$n" "is out of range (0, or 1e-30"
done
xscene hole200 'plane detect at 0 0 1 normal 0 0 1 disc 1 hole 1e-200' 'source ray from 0 0 0 dir 0 0 1'
check "extreme: 'hole 1e-200' is refused with the range" x_refused hole200 "out of range"
xscene dir170 'plane detect at 0 0 1 normal 0 0 1 disc 1' 'source ray from 0 0 0 dir 0 0 1e-170'
check "extreme: 'dir 0 0 1e-170' is refused with the range, not called zero" x_refused dir170 \
    "'1e-170' is out of range"
xscene coll310 'plane detect at 0 0 1 normal 0 0 1 disc 1' \
    'source collimated from 0 0 0 dir 0 0 1 radius 1e-310 grid 5'
check "extreme: 'collimated radius 1e-310' is refused, not silently empty" x_refused coll310 "out of range"
xscene gauss310 'plane detect at 0 0 1 normal 0 0 1 disc 1' \
    'source gaussian from 0 0 0 dir 0 0 1 waist 1e-310 wavelength 1e-3 rings 3'
check "extreme: 'waist 1e-310' is refused, not NaN powers with exit 0" x_refused gauss310 "out of range"

# coincident surfaces
xscene twoplanes 'plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 5' \
    'plane refract 1.5 1 at 0 0 0 normal 0 0 1 disc 5' 'plane detect at 0 0 10 normal 0 0 1 disc 100' \
    'source collimated from 0 0 -5 dir 0 0 1 radius 4 grid 9' 'reflections off' 'output summary s.sum'
x_two() {
    x_traced twoplanes 69 || return 1
    awk '$1 == "interactions" && $2 != 138 { exit 1 } $1 == "medium_mismatch" && $2 != 0 { exit 1 }
         $1 == "detected" { d = $2 } END { exit !(d > 0.92159 && d < 0.92161) }' "$XW/twoplanes/s.sum"
}
check "extreme: two planes 1 -> 1.5 -> 1 at one z are both met, in order (T = 0.96^2)" x_two
xscene badchain 'plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 5' \
    'plane refract 1.6 1 at 0 0 0 normal 0 0 1 disc 5' 'source ray from 0 0 -1 dir 0 0 1'
check "extreme: coincident planes whose media do not chain are refused with both lines" x_refused \
    badchain "badchain.scene:2: this plane coincides with the plane of line 1 and their media do not chain"
xscene partial 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 5' \
    'cap refract 1.5 1.6 vertex 0 0 0 radius 20 aperture 4' 'source ray from 0 0 -1 dir 0 0 1'
check "extreme: a cap repeated with a partly overlapping aperture is refused with both lines" \
    x_refused partial "partial.scene:2: this cap lies on the cap of line 1"
xscene doublet 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 5' \
    'cap refract 1.5 1.6 vertex 0 0 0 radius 20 aperture 5' 'plane detect at 0 0 30 normal 0 0 1 disc 50' \
    'source collimated from 0 0 -5 dir 0 0 1 radius 4.5 grid 41' 'output summary s.sum'
x_doublet() {
    xtrace "$BIN" doublet || { cat "$XW/doublet/err"; return 1; }
    awk '$1 == "cut_depth" && $2 != 0 { exit 1 } $1 == "medium_mismatch" && $2 != 0 { exit 1 }' \
        "$XW/doublet/s.sum"
}
check "extreme: a cemented pair of caps sharing vertex and radius traps no ray" x_doublet

# the tessellated glass sphere: the on-axis ray refracts at the pole (T = 0.96^2)
xscene tess400 'sphere refract 1 1.5 center 0 0 0 radius 1 tessellate 400' \
    'plane detect at 0 0 5 normal 0 0 1 disc 10' 'source ray from 0 0 -5 dir 0 0 1' \
    'reflections off' 'output summary s.sum'
x_tess() {
    x_traced tess400 1 || return 1
    awk '$1 == "interactions" && $2 != 2 { exit 1 }
         $1 == "detected" { d = $2 } END { exit !(d > 0.92159 && d < 0.92161) }' "$XW/tess400/s.sum"
}
check "extreme: sphere tessellate 400: the on-axis ray meets both poles (no hole)" x_tess

# a tessellated singlet far from the origin (x = 1e7) against the analytic one there:
# the same hits, to the rounding of 1e7 (Embree's coordinates are relative to its box)
for t in an ts; do
    tess=''; [ "$t" = ts ] && tess='tessellate 32 refine'
    xscene "far$t" "cap refract 1 1.5168 vertex 1e7 0 0 radius 50 aperture 12 $tess" \
        "cap refract 1.5168 1 vertex 1e7 0 8 radius -50 aperture 12 $tess" \
        'plane detect at 1e7 0 55.0190998600405 normal 0 0 1 disc 30' \
        'source collimated from 1e7 0 -10 dir 0 0 1 radius 10 grid 21' 'fresnel off' \
        'output hits h.csv' 'output summary s.sum'
done
x_far_tess() {
    x_traced faran 349 && x_traced farts 349 || return 1
    grep -q '^medium_mismatch 0$' "$XW/farts/s.sum" || { echo "index mismatches"; return 1; }
    awk -F, 'NR == FNR { if (FNR > 1) p[$1 "," $2] = $5 " " $6; next }
             FNR > 1 { k = $1 "," $2; if (!(k in p)) bad = 1; split(p[k], a, " ")
                       dx = a[1] - $5; dy = a[2] - $6; if (dx < 0) dx = -dx; if (dy < 0) dy = -dy
                       if (dx > 4e-9 || dy > 4e-9) bad = 1 }
             END { exit bad }' "$XW/faran/h.csv" "$XW/farts/h.csv"
}
check "extreme: a tessellated singlet at x = 1e7 hits where the analytic one does (to 4e-9)" x_far_tess

# crossing surfaces: refracting planes that cross inside both apertures are refused,
# mirrors may meet, planes whose apertures end before the line they share pass
xscene crossing 'plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 5' \
    'plane refract 1.5 1 at 0 0 1 normal 0 1 1 rect 4 4' 'source ray from 0 0 -1 dir 0 0 1'
check "extreme: refracting planes that cross inside their apertures are refused with both lines" \
    x_refused crossing "crossing.scene:2: this refracting plane crosses the one of line 1"
xscene apart 'plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 5' \
    'plane refract 1.5 1 at 0 0 10 normal 0 0.2 1 disc 5' 'plane detect at 0 0 40 normal 0 0 1 disc 99' \
    'source ray from 0 0 -1 dir 0 0 1' 'reflections off'
check "extreme: refracting planes whose apertures do not reach their common line are traced" \
    x_traced apart 1

# the same bits on any thread count: coincident caps, a closed tessellated sphere
for th in 1 2; do
    xscene "thr$th" 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 5' \
        'cap refract 1.5 1.6 vertex 0 0 0 radius 20 aperture 5' \
        'sphere refract 1.6 1.2 center 0 0 12 radius 3 tessellate 40' \
        'plane detect at 0 0 30 normal 0 0 1 disc 50' \
        'source collimated from 0 0 -5 dir 0 0 1 radius 4.5 grid 61' "threads $th" \
        'output hits h.csv' 'output summary s.sum'
done
x_threads() {
    xtrace "$BIN" thr1 && xtrace "$BIN" thr2 || return 1
    cmp "$XW/thr1/h.csv" "$XW/thr2/h.csv" &&       # the summary's line 1 names the scene
        [ "$(tail -n +2 "$XW/thr1/s.sum")" = "$(tail -n +2 "$XW/thr2/s.sum")" ]
}
check "extreme: coincident caps and a closed mesh give the same bits on 1 and 2 threads" x_threads

# crossing surfaces of revolution on one axis: refused; touching at the vertex: traced
xscene capcross 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 5' \
    'cap refract 1.5 1 vertex 0 0 0.2 radius 50 aperture 5' 'source ray from 0 0 -1 dir 0 0 1'
check "extreme: two caps that cross inside their apertures are refused with both lines" \
    x_refused capcross "capcross.scene:2: the surfaces cross"
xscene disccross 'cap refract 1 1.5 vertex 0 0 0 radius 20 aperture 5' \
    'plane refract 1.5 1 at 0 0 0.3 normal 0 0 1 disc 5' 'source ray from 0 0 -1 dir 0 0 1'
check "extreme: a disc cutting through a cap is refused with both lines" \
    x_refused disccross "disccross.scene:2: this refracting plane crosses the cap of line 1"
