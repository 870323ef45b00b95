# t_89_scan_time.sh -- the scan planner (tests/rig/t_scan.c, doc/scan-time.md): the
# planned order visits every target once and is deterministic, the simulated run
# stays within the axes' speed and acceleration (checked on the simulator's log),
# exposes only settled and at rest, and takes less time than the spiral's own order;
# both builds.
# (unit runs them from the top folder: t_scan reads golden/rig/example.rig there)
unit "$TOP/build/obj/rig_tests/t_scan"
unit "$TOP/build/asan/rig_tests/t_scan"
