# t_96_zone.sh -- the clinical zone and the ISO 19980 report (issue 19 items 4, 5).
# tests/topo/t_zone.c: the pipeline's adaptive plan (topo_api.measure_zone) on the
# wide-zone rig, every spot from an independent forward model written for the test
# (spheres of R 6.5, 7.8, 9.5, a conic asphere, a toric moved and tilted, a cone):
# the zone covered >= 8 mm and no spot off the sensor, a plan on the nominal cornea
# losing spots on R 6.5, the ISO statistics in the central 6 mm within 1 um (mean) and
# 3 um (2SD) of the true surfaces, and their arithmetic against a closed form.  The
# sanitizer build runs two surfaces at 300 points.
unit "$TOP/build/obj/topo_tests/t_zone"
if [ -x "$TOP/build/asan/topo_tests/t_zone" ]; then
    "$TOP/build/asan/topo_tests/t_zone" quick > "$WORK/unit.out" 2>&1; rc=$?
    p=$(grep -c '^PASS' "$WORK/unit.out"); f=$(grep -c '^FAIL' "$WORK/unit.out")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$WORK/unit.out" | sed 's|^|asan/t_zone: |'
    [ "$rc" -eq 0 ] || [ "$f" -gt 0 ] || fail "asan t_zone exited $rc"
else fail "$TOP/build/asan/topo_tests/t_zone (not built)"; fi
