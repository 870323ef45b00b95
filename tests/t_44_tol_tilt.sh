# t_44_tol_tilt.sh -- tilt and decentre tolerances and folded lenses in the design
# module (src/design: a coordinate break and its inverse around the perturbed surface
# or element; first order unfolded, rays folded) and --wave on folded lenses:
#  - tests/design/t_toltilt.c (both builds): the boresight of every surface and
#    element tilt and decentre of Sasian's triplet against a first-order closed form,
#    the Monte Carlo against the RSS and second-order predictions, a fold mirror's
#    tilt against L tan 2theta, a Cassegrain's secondary conic, a fold in optimisation;
#  - --tolerance on a Newtonian (doc/design/newtonian.rx): a mirror tilted by theta
#    turns the beam by 2 theta, so the image moves by 2 theta times the distance to the
#    (refocused) image plane; a decentred paraboloid takes its focus with it; replay;
#    the Monte Carlo in jobs under GNU parallel = one process;
#  - --optimise on a Cassegrain (doc/design/cassegrain.rx) finds the classical
#    secondary, k2 = -((m + 1)/(m - 1))^2 = -2.25; replay;
#  - --wave: the Newtonian's axis wavefront is flat (the diagonal adds nothing), a
#    singlet folded by a 45-degree mirror has the wavefront of the singlet straight,
#    a spherical mirror tilted by alpha has the astigmatism of Coddington's foci
#    f cos(alpha), f / cos(alpha): Fringe Z5 = (h^2 / 4)(1/f_t - 1/f_s) / lambda;
#  - refusals with FILE:LINE.
unit "$TOP/build/obj/design_tests/t_toltilt"
unit "$TOP/build/asan/design_tests/t_toltilt"

tt_dir() { mkdir -p "$WORK/tt" && ln -sfn "$TOP/doc" "$WORK/tt/doc"; }

# The Newtonian's sensitivities: the rows' boresight shifts (um) against the closed
# forms on the refocused plane (the nominal refocus dz: the image 100 + dz from the
# primary, 20 + dz from the diagonal); theta 0.02 and 0.05 degrees.
tt_newt_sens() (
    tt_dir && cd "$WORK/tt" && printf 'doc/design/newtonian.rx\n-\nsens\n' > ns.in &&
    "$1" --tolerance -i ns.in ns.rec > /dev/null || return 1
    awk 'function near(v, w) { return (v - w) ^ 2 <= (2e-5 * w) ^ 2 }
         function deg(a) { return a * 3.14159265358979323846 / 180 }
         /nominal: RMS/ { for (i = 1; i <= NF; i++) if ($i == "refocus") dz = $(i + 1) }
         $1 == "tx" && $2 == 1 { p = $13 } $1 == "ty" && $2 == 1 { q = $12 }
         $1 == "dx" && $2 == 1 { dx = $12 } $1 == "tx" && $2 == 3 { d = $13 }
         $1 == "ty" && $2 == 3 { e = $12 }
         END { P = 2 * deg(0.02) * (100 + dz) * 1e3; D = 2 * deg(0.05) * (20 + dz) * 1e3
               E = 2 * cos(deg(45)) * deg(0.05) * (20 + dz) * 1e3
               printf "primary tilt %s / %s, diagonal %s / %s, about y %s / %s, decentre %s um\n", p, P, d, D, e, E, dx
               exit !(near(p, P) && near(-q, P) && near(-d, D) && near(e, E) && dx == 50) }' ns.rec || return 1
    grep -q 'linear prediction: sd x' ns.rec &&
    grep input: ns.rec > ns2.in && "$1" --tolerance ns2.rec < ns2.in > /dev/null && cmp ns.rec ns2.rec
)
check "--tolerance, Newtonian: mirror tilts move the image 2 theta x distance, a decentre 1:1; replays" tt_newt_sens "$BIN"
check "--tolerance, Newtonian: the same under ASan/UBSan" tt_newt_sens "$ASAN"

# The Monte Carlo of the Newtonian with its tilts: the table's boresight columns and
# summary; 4 jobs under GNU parallel give one process's table and summary exactly.
tt_newt_mc() (
    cd "$WORK/tt" || return 1
    LENSMAT=$1 sh "$TOP/scripts/tolerance-mc.sh" -f doc/design/newtonian.rx \
        -N 200 -C 50 -s 5 -l 2 -j 2 -o npar > npar.out || return 1
    printf 'doc/design/newtonian.rx\n-\nmc\n200\n1\n5\nuniform\nbfd\n2\nnone.tab\n' > none.in &&
    "$1" --tolerance -i none.in none.rec > /dev/null || return 1
    cmp npar/table.txt none.tab && head -1 none.tab | grep -q '^# lens rms_um efl bfd focus bx_um by_um$' &&
    grep -q '^  boresight um: x mean ' none.rec || return 1
    grep -E '^  (.* lenses \(|RMS um|efl mean|boresight|yield)' none.rec > a.txt &&
    grep -E '^  (.* lenses \(|RMS um|efl mean|boresight|yield)' npar/summary.rec > b.txt && cmp a.txt b.txt
)
check "tolerance-mc.sh, Newtonian with tilts: 4 jobs = one process (table with boresight, summary)" tt_newt_mc "$BIN"

# --optimise on the Cassegrain with a spherical secondary: k2 found at -2.25.
tt_cass() (
    tt_dir && cd "$WORK/tt" && rm -f cass-opt.rx &&
    printf 'doc/design/cassegrain.rx\n-\n50\ncass-opt.rx\n' > co.in &&
    "$1" --optimise -i co.in co.rec > /dev/null || return 1
    awk '/variables at the end/ { on = 1 } on && $1 == "k" && $2 == 2 { k = $3 }
         END { printf "k2 %s\n", k; exit !(k != "" && (k + 2.25) ^ 2 < 1e-16) }' co.rec || return 1
    grep -q 'conic -2.2499999' cass-opt.rx || grep -q 'conic -2.25 ' cass-opt.rx || return 1
    rm -f cass-opt.rx && grep input: co.rec > co2.in && "$1" --optimise co2.rec < co2.in > /dev/null &&
        cmp co.rec co2.rec
)
check "--optimise, Cassegrain: the secondary's conic for the least spot is -((m+1)/(m-1))^2 = -2.25; replays" tt_cass "$BIN"
check "--optimise, Cassegrain: the same under ASan/UBSan" tt_cass "$ASAN"

# --wave on folded lenses.
tt_wave() {  # BIN LENS NAME: 64 cells, Fringe 37, no MTF range, no focus run
    printf '%s\n64\nfringe\n37\n0\n0\n1\n50\n-\n' "$2" > "$WORK/tt/$3.in"
    (cd "$WORK/tt" && "$1" --wave -i "$3.in" "$3.rec" > "$3.out" 2> "$3.err")
}
cat > "$WORK/tt-tsph.rx" <<'RX'
thickness
title spherical mirror tilted 5 degrees
wavelengths d
epd 10
field angle 0
index air
plane     20    air  stop
coordbrk  0     tilt 5 0 0
-200      0     air  mirror
coordbrk  -100  tilt 5 0 0
RX
cat > "$WORK/tt-fold.rx" <<'RX'
thickness
wavelengths d
epd 10
field angle 0 3
102       4     1.5168  stop
-102      30    air
coordbrk  0     tilt 45 0 0
plane     0     air  mirror
coordbrk  -66   tilt 45 0 0
RX
sed -e '/coordbrk\|mirror/d' -e 's/^-102      30 /-102      96 /' "$WORK/tt-fold.rx" > "$WORK/tt-straight.rx"
tt_wave_fold() {
    tt_dir && sed '/^tol /d' "$TOP/doc/design/newtonian.rx" > "$WORK/tt/newt.rx"
    tt_wave "$1" newt.rx wn || { cat "$WORK/tt/wn.err"; return 1; }
    awk '/^Field 1:/ { on = 1 } on && /W RMS/ { ok = ($0 ~ /W RMS 0.0000 PV 0.0000 waves; Strehl 1.0000/); exit !ok }' "$WORK/tt/wn.rec" || return 1
    tt_wave "$1" "$WORK/tt-fold.rx" wf && tt_wave "$1" "$WORK/tt-straight.rx" ws || return 1
    grep -E 'W RMS|^ +[0-9]+ +[0-9]+ +-?[0-9]+ +-?[0-9.]+ ' "$WORK/tt/wf.rec" > "$WORK/tt/wf.k" &&
    grep -E 'W RMS|^ +[0-9]+ +[0-9]+ +-?[0-9]+ +-?[0-9.]+ ' "$WORK/tt/ws.rec" > "$WORK/tt/ws.k" &&
    [ -s "$WORK/tt/wf.k" ] && cmp "$WORK/tt/wf.k" "$WORK/tt/ws.k" || return 1
    tt_wave "$1" "$WORK/tt-tsph.rx" wt || { cat "$WORK/tt/wt.err"; return 1; }
    awk '$1 == 5 && $5 ~ /astig/ { c = $4 }
         END { a = 5 * 3.14159265358979323846 / 180
               w = 25 / 4 * (1 / cos(a) - cos(a)) / 100 / 587.5618e-6
               printf "Z5 %s waves, Coddington %.5f\n", c, w
               exit !(c != "" && ((-c) - w) ^ 2 < (0.005 * w) ^ 2) }' "$WORK/tt/wt.rec"
}
check "--wave, folded: a Newtonian's axis wavefront flat, a fold = straight, a tilted sphere's astigmatism = Coddington's" tt_wave_fold "$BIN"
check "--wave, folded: the same under ASan/UBSan" tt_wave_fold "$ASAN"

# Refusals (FILE:LINE, exit 2): overlapping elements, an element kind on one surface,
# a tilt of 45 degrees or more, a tilt of a coordinate break, an element holding one
# (the group's inverse break would not commute with it).
tt_bad() (
    tt_dir && cd "$WORK/tt" || return 1
    one() {  # TOLFILE-TEXT EXPECTED [LENS]
        printf '%b' "$1" > bad.tol
        printf '%s\nbad.tol\n' "${3:-doc/design/newtonian.rx}" > bad.in
        "$BIN" --tolerance -i bad.in bad.rec > /dev/null 2> bad.err; rc=$?
        [ $rc -eq 2 ] && grep -q "$2" bad.err || { echo "rc $rc"; cat bad.err; return 1; }
    }
    one 'tol tx 1-3 0.1\ntol ty 3-4 0.1\n' 'bad.tol:2: surfaces 3-4 overlap the element 1-3' \
        doc/design/sasian-triplet.rx &&
    one 'tol tetx 1 0.1\n' "bad.tol:1: 'tetx' tilts or decentres an element: give its surfaces S-E" &&
    one 'tol tx 1 45\n' "bad.tol:1: '45': a tilt tolerance is in degrees, < 45" &&
    one 'tol dy 2 0.1\n' 'bad.tol:1: surface 2 is a coordinate break: tilt or decentre the surface after it' &&
    one 'tol tx 1-3 0.1\n' 'bad.tol:1: surface 2 is a coordinate break: an element that tilts or decentres as one holds surfaces only'
)
check "--tolerance: overlapping elements, an element tilt of one surface, 45 degrees, a break, an element with a break: FILE:LINE" tt_bad
