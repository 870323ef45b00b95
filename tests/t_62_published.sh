# t_62_published.sh -- lensmat against published lenses whose numbers others can
# check (tests/published/, each file names its source): Sasian's Cooke triplet's
# Seidel sums, transverse aberrations and first-order data as ray-optics prints them
# (tests/unit_published.c, which also checks the chromatic sums and the real-ray h^3
# trend through the tracer), the tracer's own view of the same lens
# (tests/trace/t_published.c), and the classic dialogue's cardinal points from the
# prescription file against the published first-order data.
PUBDIR=$TOP/tests/published
LENSMAT_LIBDIR=$TOP/build/lib unit "$TOP/build/obj/unit_published"
LENSMAT_LIBDIR=$TOP/build/asan/lib unit "$TOP/build/asan/unit_published"
unit "$TOP/build/obj/trace_tests/t_published"
unit "$TOP/build/asan/trace_tests/t_published"

# The classic dialogue reads the prescription file (positions, glass names): its
# printed first-order lines against ray-optics' first_order_data (4 digits):
# efl 50, ffl -37.1 (first focal point), pp1 12.9, bfl 41.24 (second focal point
# 60.85 - 19.615), ppk -8.763 (principal plane 2 - 19.615).
pub_classic() {
    "$BIN" --prescription -i "$PUBDIR/sasian_triplet.txt" "$WORK/sasian.rec" > "$WORK/sasian.out" ||
        return 1
    awk -v tol=0 '
        function near(v, want, t) { return (v - want) <= t && (want - v) <= t }
        /^Focal distance:/      { f = $3 }
        /^First focal point:/   { f1 = $5 }
        /^Second focal point:/  { f2 = $5 }
        /^Principal plane 1,/   { h1 = $5 }
        /^Principal plane 2,/   { h2 = $5 }
        END {
            ok = near(f, 50, 0.005) && near(f1, -37.1, 0.05) && near(h1, 12.9, 0.05) &&
                 near(f2 - 19.615, 41.24, 0.005) && near(h2 - 19.615, -8.763, 0.0005)
            printf "efl %s ffl %s pp1 %s bfl %.4f ppk %.4f\n", f, f1, h1, f2 - 19.615, h2 - 19.615
            exit !ok
        }' "$WORK/sasian.out"
}
check "Sasian triplet from its prescription file: classic first order = ray-optics' (4 digits)" pub_classic
