#!/bin/sh
# bench_paraxial.sh -- the paraxial engine: surfaces per second for a 10 000-surface
# system (build + first-order analysis with condition estimates + one image), and
# |det - 1| after a 10 000-surface periodic relay (accurate and listing-order
# products).  See tests/bench_paraxial.c.
set -e
build/obj/bench_paraxial "${BENCH_RUNS_PARAXIAL:-21}"
