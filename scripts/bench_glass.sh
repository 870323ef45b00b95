#!/bin/sh
# bench_glass.sh -- the glass catalogue against its sources' printed nd and Vd, the
# Thorlabs AC254-100-A achromat's paraxial focal lengths against the vendor's and its
# F-C focal shift, and the cost of an index by name.  See tests/bench_glass.c.
set -e
echo "bench_glass on $(uname -m),$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2), $(nproc) cpus"
build/obj/bench_glass "${BENCH_RUNS_GLASS:-21}"
