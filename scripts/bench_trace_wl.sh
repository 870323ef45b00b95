#!/bin/sh
# bench_trace_wl.sh -- the tracer per wavelength (issue 14), through `lensmat --trace`
# on scene files:
#   trace_dispersion_rel_err  the largest relative error of a 30-degree prism's
#       deviation traced at 8 wavelengths (F d C e g, 632.8, 400, 700 nm) in N-BK7,
#       N-SF6 and fused silica, against Snell's law with the index computed here (awk)
#       from data/glass.txt's coefficients;
#   trace_wl_column_speed_ratio  rays/s of a singlet in a collimated 301 x 301 grid
#       (71 000 rays, hits written to a CSV) whose glass is named with `lambda d` (the
#       lambda column written), against the same scene with plain indices (no column):
#       the cost of the column and of the per-wavelength set-up;
#   trace_absorb_speed_ratio  the same with an absorbing glass (N-BK7: Beer-Lambert
#       on every segment inside, ray by ray), against plain indices.
# Medians of 5 runs each, the pairs run back to back; the machine is printed.
set -e
RUNS=${BENCH_WL_RUNS:-5}
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT
LM=$(pwd)/lensmat
GLASS=$(pwd)/data/glass.txt
echo "# bench_trace_wl on: $(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo),\
 $(nproc) cores"

trace() {   # DIR: lensmat --trace on DIR/s.scene; prints the trace's rays/s
    printf 'scene\ns.scene\nn\n' > "$1/in"
    (cd "$1" && "$LM" --trace -i in r.rec > out 2> err) || { cat "$1/err" >&2; exit 1; }
    sed -n 's/.*trace [0-9.e+]* ms (\([0-9.e+]*\) rays\/s).*/\1/p' "$1/out"
}

# ---- dispersion: prism deviation against Snell ----
worst=0
for g in N-BK7 N-SF6 F_SILICA; do
    d=$W/prism_$g; mkdir -p "$d"
    printf '%s\n' \
        "plane refract 1 $g at 0 0 0 normal 0 0 1 disc 8" \
        "plane refract $g 1 at 0 0 10 normal 0 -0.5 0.8660254037844386 disc 8" \
        "plane detect at 0 0 60 normal 0 0 1 rect 400 400" \
        "source ray from 0 0 -5 dir 0 0 1 lambda F d C e g 632.8 400 700" \
        "reflections off" "output hits h.csv" > "$d/s.scene"
    trace "$d" > /dev/null
    e=$(awk -F, -v g="$g" 'FNR == NR { m = split($0, f, " ")   # (the catalogue: blanks)
                                       if (f[1] == g && f[2] ~ /^sellmeier/) { model = f[2]
                                           for (i = 7; i <= m; i++) c[i] = f[i]; nf = m }
                                       next }
        FNR > 1 { l = $16 / 1000; l2 = l * l; n2 = 1
                  for (i = 7; i < nf; i += 2) { k = c[i + 1]; if (model == "sellmeier-l") k = k * k
                                                n2 += c[i] * l2 / (l2 - k) }
                  pi = atan2(0, -1); a = pi / 6; s = sqrt(n2) * sin(a)
                  want = atan2(s, sqrt(1 - s * s)) - a
                  got = atan2(sqrt($8 * $8 + $9 * $9), $10)
                  r = (got - want) / want; if (r < 0) r = -r; if (r > w) w = r; rows++ }
        END { if (rows != 8) { print "rows " rows > "/dev/stderr"; exit 1 }; printf "%.3g\n", w }' \
        "$GLASS" "$d/h.csv")
    worst=$(awk -v a="$worst" -v b="$e" 'BEGIN { print (b > a ? b : a) }')
done
echo "BENCH trace_dispersion_rel_err $worst rel (30-degree prisms, N-BK7 N-SF6 F_SILICA, 8 wavelengths each)"

# ---- speed: plain indices, a glass with the lambda column, an absorbing glass ----
singlet() {   # DIR N LAMBDA
    mkdir -p "$1"
    printf '%s\n' \
        "cap refract 1 $2 vertex 0 0 0 radius 50 aperture 12" \
        "cap refract $2 1 vertex 0 0 8 radius -50 aperture 12" \
        "plane detect at 0 0 55.0190998600405 normal 0 0 1 disc 30" \
        "source collimated from 0 0 -10 dir 0 0 1 radius 10 grid 301 $3" \
        "output hits h.csv" > "$1/s.scene"
}
singlet "$W/plain" 1.5168 ""
singlet "$W/column" 1.5168/64.17 "lambda d"
singlet "$W/absorb" N-BK7 "lambda d"
i=0
: > "$W/speeds"
while [ $i -lt "$RUNS" ]; do
    echo "$(trace "$W/plain") $(trace "$W/column") $(trace "$W/absorb")" >> "$W/speeds"
    i=$((i + 1))
done
[ "$(head -1 "$W/column/h.csv" | tr ',' '\n' | tail -1)" = lambda_nm ] || exit 1
awk '{ p[NR] = $1; c[NR] = $2; a[NR] = $3 }
    function med(x, n,   i, j, t) { for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
                                       if (x[j] < x[i]) { t = x[i]; x[i] = x[j]; x[j] = t }
                                   return x[int((n + 1) / 2)] }
    END { mp = med(p, NR); mc = med(c, NR); ma = med(a, NR)
          printf "BENCH trace_wl_plain_rays_per_s %.4g rays/s (singlet, 71k rays, hits CSV)\n", mp
          printf "BENCH trace_wl_column_speed_ratio %.3f ratio (model glass at lambda d, lambda column / plain indices)\n", mc / mp
          printf "BENCH trace_absorb_speed_ratio %.3f ratio (N-BK7 absorbing, ray by ray / plain indices)\n", ma / mp }' \
    "$W/speeds"
