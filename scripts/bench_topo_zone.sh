#!/bin/sh
# bench_topo_zone.sh -- the clinical zone and the ISO 19980 report (issue 19 items 4,
# 5; tests/topo/t_zone.c): on the wide-zone rig (golden/rig/wide-zone.rig) with spots
# from an independent forward model written for the test, planned adaptively
# (topo_api.measure_zone), 800 points out to 5 mm from the axis: the smallest zone
# diameter covered on the spheres of R 6.5, 7.8 and 9.5 mm (topo_zone_mm), and over
# the test surfaces (those spheres, a conic asphere, a toric, a cone) in the central
# 6 mm the worst area-weighted mean difference against the true surface
# (topo_mean_diff_um) and twice its SD (topo_2sd_um), also in D; the spots a plan on
# the nominal cornea loses off the sensor on R 6.5 (the baseline).  The program's
# PASS/FAIL lines are dropped here (t_96 runs it as a test).
B=build/obj/topo_tests/t_zone
[ -x "$B" ] || { echo "bench_topo_zone: $B not built (make bench builds it)" >&2; exit 1; }
echo "# bench_topo_zone on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
"$B" | grep -e '^BENCH' -e '^# rig'
