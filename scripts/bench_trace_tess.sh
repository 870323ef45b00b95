#!/bin/sh
# bench_trace_tess.sh -- the error-against-run-time figures of the ray tracer: the
# tessellation table of `lensmat --trace` (choice "table") for a biconvex singlet
# (R 50/-50, 8 thick, n 1.5168, semi-diameter 12; detector at the paraxial focus),
# a 201 x 201 collimated grid (31 700 rays), run 3 times.  Per model: max and RMS
# detector error against the analytic trace (deterministic), the median build time
# and trace speed, and the triangles.  Model names: analytic, mesh<L> (flat
# triangles), mesh<L>_normal (analytic normals), mesh<L>_refine (re-intersected).
set -e
RUNS=${BENCH_TESS_RUNS:-3}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
LM=$(pwd)/lensmat
printf 'table\n50\n-50\n8\n1.5168\n12\n201\nn\n' > "$W/in"
i=0
while [ $i -lt "$RUNS" ]; do
    (cd "$W" && "$LM" --trace -i in r.rec > "out$i")
    i=$((i + 1))
done
# rows: "mesh 16 +normal  3072  build  trace  rays/s  max  rms  lost"
cat "$W"/out* | awk '
    /^analytic / || /^mesh [0-9]/ {
        name = $1; f = 2
        if ($1 == "mesh") { name = "mesh" $2; f = 3
            if ($3 == "+normal") { name = name "_normal"; f = 4 }
            else if ($3 == "+refine") { name = name "_refine"; f = 4 } }
        if (!(name in tri)) order[++n] = name
        tri[name] = $f; maxe[name] = $(f + 4); rms[name] = $(f + 5)
        speed[name] = speed[name] " " $(f + 3); build[name] = build[name] " " $(f + 1)
    }
    function median(s,   a, m, i, j, t) {
        m = split(s, a, " ")
        for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++)
            if (a[j] + 0 < a[i] + 0) { t = a[i]; a[i] = a[j]; a[j] = t }
        return a[int((m + 1) / 2)]
    }
    END {
        if (!n) { print "bench_trace_tess: no table rows" > "/dev/stderr"; exit 1 }
        for (i = 1; i <= n; i++) {
            m = order[i]
            if (m != "analytic") printf "BENCH trace_tess_%s_triangles %d triangles\n", m, tri[m]
            printf "BENCH trace_tess_%s_max_error %.3e lens_units\n", m, maxe[m]
            printf "BENCH trace_tess_%s_rms_error %.3e lens_units\n", m, rms[m]
            printf "BENCH trace_tess_%s_build_ms %.3f ms\n", m, median(build[m])
            printf "BENCH trace_tess_%s_mrays_per_s %.3f Mrays/s\n", m, median(speed[m]) / 1e6
        }
    }'
