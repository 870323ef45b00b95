#!/bin/sh
# bench_topo.sh -- corneal topography's figures (issue 19; tests/topo/t_topo.c): the
# keratoconus indices of a cone of 5 D at 1.5 mm below centre, its spots from an
# independent forward model written for the test, reconstructed from a reference
# sphere fitted to the coned eye, against the test's own computation of the true
# surface's indices (topo_kmax_err_D, topo_kmax_loc_err_mm, topo_is_err_D;
# topo_zone_radius_mm: the data's radius on the widest zone the example rig reaches),
# and the biconic fit on six test eyes of 1000 spots: the most iterations
# (cornea_fit_iterations) and the CPU time of the first on its thread (cornea_fit_s:
# the wall clock of a shared machine measures its load).  The program's PASS/FAIL
# lines are dropped here (t_93 runs it as a test).
B=build/obj/topo_tests/t_topo
[ -x "$B" ] || { echo "bench_topo: $B not built (make bench builds it)" >&2; exit 1; }
echo "# bench_topo on: $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
"$B" | grep -e '^BENCH' -e '^#'
