# t_77_centroid_plot.sh -- the centroid methods' table plotted (issue 10, sections 1
# and 3): a short run of the centroid benchmark (tests/imaging/bench_centroid.c) plots
# its own table, RMS error against time per frame on log-log axes, through the imaging
# engine's plot call; PNG and SVG written, nothing left half-written; every method's
# marker is where its row of the table says (the pixel the plot reports, recomputed
# from the table and the axes within one pixel) and the picture's pixels of the
# method's colour are centred there; a name that is not .png is refused before
# anything is measured or written.

CP=$WORK/centplot
CPB=$TOP/build/obj/imaging_tests/bench_centroid
mkdir -p "$CP"

cp_run() {
    [ -x "$CPB" ] || { echo "$CPB not built"; return 1; }
    # run from the top: the bench links build/lib/lensmat-imaging.so by that path
    "$CPB" 40 "$CP/m.tsv" "$CP/m.png" > "$CP/out" 2> "$CP/err" || { cat "$CP/err"; return 1; }
    [ -s "$CP/m.png" ] && [ -s "$CP/m.svg" ] || { ls "$CP"; return 1; }
    ! ls "$CP" | grep -q part || { ls "$CP"; return 1; }
    [ "$(grep -c . "$CP/m.tsv")" -eq 5 ] && grep -q "^PLOT written $CP/m.png $CP/m.svg (0 points left out)" "$CP/out" ||
        { cat "$CP/out"; return 1; }
    for t in 'Gaussian fit' 'moments (raw counts)' 'moments above background' \
             'Gaussian fit, tilted background' 'Cramer-Rao bound 0.0399 px' \
             'Centroid methods: RMS error against time per frame'; do
        grep -q ">$t</text>" "$CP/m.svg" || { echo "no '$t' in the SVG"; return 1; }
    done
}
check "centroid plot: a 40-frame run writes its table, PNG and SVG (labels, legend)" cp_run

# Each method's marker where the table puts it: x from the time, y from the RMS error,
# log10 between the reported axis ranges across the reported box.
cp_markers() {
    awk 'NR == FNR { if (FNR > 1) { us[$1] = $3; rms[$1] = $2; n++ }; next }
         $1 == "PLOT" && $2 == "box" { x0 = $3; y0 = $4; x1 = $5; y1 = $6
             xa = log($8) / log(10); xb = log($9) / log(10)
             ya = log($10) / log(10); yb = log($11) / log(10) }
         $1 == "PLOT" && $2 == "marker" { m = $3
             if (!(m in us)) { print "marker of an unknown method " m; bad = 1; next }
             ex = x0 + (log(us[m]) / log(10) - xa) / (xb - xa) * (x1 - x0)
             ey = y1 - (log(rms[m]) / log(10) - ya) / (yb - ya) * (y1 - y0)
             dx = $4 - ex; dy = $5 - ey
             printf "%s: table (%s us, %s px) -> pixel (%.2f, %.2f); drawn at (%s, %s)\n",
                    m, us[m], rms[m], ex, ey, $4, $5
             if (dx * dx + dy * dy > 1 || $4 < x0 || $4 > x1 || $5 < y0 || $5 > y1) bad = 1
             seen++ }
         END { if (seen != n || n != 4) { print seen " markers for " n " methods"; bad = 1 }
               exit bad }' "$CP/m.tsv" "$CP/out"
}
check "centroid plot: every method's marker sits where its table row says, within 1 px" cp_markers

# The pixels agree: around each reported marker, the pixels of its method's colour
# (the engine's palette, series 1..4 in the table's order) are centred on it within one
# pixel -- unless another marker is drawn within 9 px (one would cover the other).
cp_pixels() {
    CMP=$TOP/build/obj/imaging_tests/draw_pngcmp
    grep '^PLOT marker' "$CP/out" > "$CP/marks"
    while read -r _ _ m x y; do
        case $m in
            gauss_fit) rgb="255 127 14" ;; moments) rgb="44 160 44" ;;
            moments_bg) rgb="127 127 127" ;; gauss_fit_plane) rgb="148 103 189" ;;
            *) echo "unknown method $m"; return 1 ;;
        esac
        near=$(awk -v x="$x" -v y="$y" '{ d = ($4 - x) ^ 2 + ($5 - y) ^ 2
                 if (d > 0 && d < 81) n++ } END { print n + 0 }' "$CP/marks")
        [ "$near" -eq 0 ] || { echo "$m: another marker within 9 px, pixels not checked"; continue; }
        set -- $("$CMP" blob "$CP/m.png" "$x" "$y" $rgb) || { echo "$m: no marker at ($x, $y)"; return 1; }
        awk -v m="$m" -v x="$x" -v y="$y" -v px="$1" -v py="$2" -v w="$3" 'BEGIN {
            printf "%s: reported (%s, %s), its pixels centred at (%s, %s), weight %s\n", m, x, y, px, py, w
            exit !((px - x) ^ 2 + (py - y) ^ 2 <= 1 && w >= 15) }' || return 1
        # and the check is not blind: 15 px to the right there is no such marker
        if "$CMP" blob "$CP/m.png" "$(awk -v x="$x" 'BEGIN { print x + 15 }')" "$y" $rgb > /dev/null; then
            near=$(awk -v x="$x" -v y="$y" '{ d = ($4 - x - 15) ^ 2 + ($5 - y) ^ 2
                     if (d < 100) n++ } END { print n + 0 }' "$CP/marks")
            [ "$near" -gt 0 ] || { echo "$m: pixels of its colour 15 px away too"; return 1; }
        fi
    done < "$CP/marks"
}
check "centroid plot: the PNG's marker pixels are centred on the reported places" cp_pixels

cp_badname() {
    if "$CPB" 3 "$CP/b.tsv" "$CP/b.jpg" > "$CP/bout" 2> "$CP/berr"; then echo "exit 0"; return 1; fi
    grep -q 'b.jpg: the plot.s name must end in .png' "$CP/berr" && [ ! -e "$CP/b.jpg" ] && [ ! -e "$CP/b.tsv" ] ||
        { cat "$CP/berr"; ls "$CP"; return 1; }
}
check "centroid plot: a picture name without .png is refused before measuring, nothing written" cp_badname
