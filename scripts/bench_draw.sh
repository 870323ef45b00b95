#!/bin/sh
# bench_draw.sh -- what a picture costs.  The Cooke triplet (doc/triplet.rx) at
# infinity and 14 degrees: a --draw session that draws its layout (real rays traced,
# PNG + SVG written), against the same session answering "done" instead (the same
# questions, no picture: neither module loaded) -- the difference is the first
# picture's whole cost, modules included.  In-process figures (median of the runs):
# draw_module_load_ms, the dlopen of lensmat-imaging.so with OpenCV (the first picture
# only); draw_trace_load_ms, the trace module's (Embree's device is made on the first
# trace, inside the drawing time); imaging_draw_ms, tracing and drawing the layout;
# imaging_spot_ms, the spot diagram (2 x 817 rays).  The classic dialogue never pays
# any of it (tests/t_76).
set -e
N=${BENCH_DRAW_RUNS:-21}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
LM=$(pwd)/lensmat
R=build/bench/benchrun
[ -x "$R" ] || make -s "$R" > /dev/null
RX=$(pwd)/doc/triplet.rx
echo "# machine: $(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -1), $(nproc) cores"
printf '%s\n' "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 14 1 layout "$W/p.png" spot 587.6 "$W/s.png" done > "$W/pic.in"
printf '%s\n' "$RX" 8,8,5.5,5.5,7.5,7.5 mm inf 14 1 done > "$W/none.in"
pic=$($R "$N" "$W/pic.in" "$LM" --draw "$W/a.rec")
none=$($R "$N" "$W/none.in" "$LM" --draw "$W/b.rec")
i=0
while [ $i -lt "$N" ]; do
    "$LM" --draw -i "$W/pic.in" "$W/c.rec" | grep '^Drawn in' >> "$W/times"
    i=$((i + 1))
done
echo "BENCH draw_session_ms $pic ms"
echo "BENCH draw_no_picture_ms $none ms"
awk -v a="$pic" -v b="$none" 'BEGIN { printf "BENCH draw_first_pictures_ms %.3f ms\n", a - b }'
awk 'function median(v, n,   i, j, t) {
         for (i = 2; i <= n; i++) for (j = i; j > 1 && v[j - 1] > v[j]; j--) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
         return v[int((n + 1) / 2)] }
     NR % 2 == 1 { load[++nl] = $9; draw[nl] = $3; tl[nl] = $14 }
     NR % 2 == 0 { spot[++ns] = $3 }
     END { printf "BENCH draw_module_load_ms %.3f ms\n", median(load, nl)
           printf "BENCH draw_trace_load_ms %.3f ms\n", median(tl, nl)
           printf "BENCH imaging_draw_ms %.3f ms\n", median(draw, nl)
           printf "BENCH imaging_spot_ms %.3f ms\n", median(spot, ns) }' "$W/times"
