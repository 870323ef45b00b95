#!/bin/sh
# bench_glass.sh -- the glass catalogue against its sources' printed nd and Vd, the
# Thorlabs AC254-100-A achromat's paraxial focal lengths against the vendor's and its
# F-C focal shift, Laikin's achromat's F-C focal shift by the paraxial engine against
# real rays (paraxial_chromatic_err), the materials the catalogues give (glass_count:
# the built-in ones and every AGF file in $LENSMAT_GLASS_PATH, data/agf, ../shared/glass;
# 500 and more need the makers' AGF files in ../shared/glass), the AGF reader's speed
# on the test catalogues, and the cost of an index by name.  See tests/bench_glass.c.
set -e
echo "bench_glass on $(uname -m),$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2), $(nproc) cpus"
build/obj/bench_glass "${BENCH_RUNS_GLASS:-21}"
# which AGF files glass_count counted (none: the built-in catalogue only)
for d in ${LENSMAT_GLASS_PATH:+$(echo "$LENSMAT_GLASS_PATH" | tr : ' ')} data/agf ../shared/glass; do
    [ -d "$d" ] && ls "$d" | grep -i '\.agf$' | sed "s|^|bench_glass: AGF catalogue $d/|"
done
true
