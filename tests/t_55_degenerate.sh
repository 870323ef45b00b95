# t_55_degenerate.sh -- the inputs on which the original prints nan/inf, loops or
# computes nonsense (golden/degenerate/*.in): lensmat gives sane, stated results.

# run_deg NAME [MODE]: run golden/degenerate/NAME.in into $WORK/deg.{out,rec}
run_deg() {
    (cd "$WORK" && timeout 10 "$BIN" $2 deg.rec < "$GOLDEN/degenerate/$1.in" > deg.out 2> deg.err)
}
# has PATTERN: both stdout and record contain the fixed string
has() { grep -qF -- "$1" "$WORK/deg.out" && grep -qF -- "$1" "$WORK/deg.rec"; }
# no nan or inf anywhere; no -0 either, except with --original (the original's bytes)
no_nan() { ! grep -Eiq '(^|[ =])-?(nan|inf)( |$)' "$WORK/deg.out" "$WORK/deg.rec" &&
    { [ "$MODE" = --original ] ||
      ! grep -Eq '(^|[ =])-0( |$)' "$WORK/deg.out" "$WORK/deg.rec"; }; }

deg_afocal_telescope() { run_deg afocal_telescope $1 && no_nan && has "is afocal" &&
    has "Afocal angular magnification: -1 " && has "Image plane, z= 2 " &&
    has "Magnification, z= -1 " && ! grep -q "Principal plane" "$WORK/deg.out"; }
deg_no_index_change() { run_deg afocal_no_index_change $1 && no_nan && has "is afocal" &&
    has "Afocal angular magnification: 1 " && has "Image plane, z= -10 " &&
    has "Magnification, z= 1 "; }
deg_radius_zero() { run_deg radius_zero $1 && no_nan && has "is afocal" &&
    has "Image plane, z= -15 " && has "Afocal angular magnification: 0.666667 " &&
    grep -q "^lens radius=           plane, lens location=               0 $" "$WORK/deg.rec"; }
deg_object_at_focus() { run_deg object_at_focus $1 && no_nan &&
    has "Image plane at infinity" && has "Angular Magnification, z= 8.33333 "; }
deg_object_at_first_surface() { run_deg object_at_first_surface $1 && no_nan &&
    has "Image plane, z= 0 " && has "Magnification, z= 1 "; }
# Y, yes: taken as y (the original ends the loop on Y and misreads the rest)
deg_yes_word() {
    run_deg "$1" && cp "$WORK/deg.rec" "$WORK/yes.rec" &&
    sed 's/^Y$/y/; s/^yes$/y/' "$GOLDEN/degenerate/$1.in" > "$WORK/y.in" &&
    (cd "$WORK" && "$BIN" deg.rec < y.in > /dev/null) && cmp "$WORK/deg.rec" "$WORK/yes.rec"
}
deg_plane_word() {
    printf '25 1 plane 0 1.5 y -3 1 1 n -10 n\n' > "$WORK/p.in" &&
    (cd "$WORK" && "$BIN" p.rec < p.in > p.out) && grep -q '^input: plane$' "$WORK/p.rec" &&
    printf '25 1 inf 0 1.5 y -3 1 1 n -10 n\n' > "$WORK/p2.in" &&
    (cd "$WORK" && "$BIN" p2.rec < p2.in > p2.out) && cmp "$WORK/p.rec" "$WORK/p2.rec" &&
    # a plane then a -3 surface = plano-convex lens, f = 3/0.5 = 6 from the curved side
    grep -q "^Second focal point: z= 7 $" "$WORK/p.rec"
}

for m in "" --original; do
    MODE=$m
    check "degenerate afocal telescope $m" deg_afocal_telescope $m
    check "degenerate no index change $m" deg_no_index_change $m
    check "degenerate radius 0 is a plane $m" deg_radius_zero $m
    check "degenerate object at focus $m" deg_object_at_focus $m
    check "degenerate object at first surface $m" deg_object_at_first_surface $m
done
check "degenerate Y taken as y" deg_yes_word answer_upper_Y
check "degenerate yes taken as y" deg_yes_word answer_yes_word
check "degenerate plane and inf radius" deg_plane_word
