#!/bin/sh
# cornea-compare.sh -- compare two cornea reports (the CSV that `lensmat --cornea-scan`
# writes as NAME.csv): for every clinical number both hold, the difference B - A, the
# combined standard uncertainty sqrt(sd_A^2 + sd_B^2) and their ratio z; a number
# whose |z| > 3 is marked "DIFFERS" (the two scans disagree beyond what each says it
# knows).  Exit 0 when none differs, 1 when one does, 2 on bad use.
#     scripts/cornea-compare.sh A.csv B.csv
set -e
if [ $# -ne 2 ] || [ ! -r "$1" ] || [ ! -r "$2" ]; then
    echo "usage: $0 A.csv B.csv (two cornea reports)" >&2
    exit 2
fi
for f in "$1" "$2"; do
    grep -q '^format,lensmat-cornea-report 1,' "$f" ||
        { echo "$0: $f is not a lensmat cornea report" >&2; exit 2; }
done
awk -F, -v A="$1" -v B="$2" '
BEGIN { n = split("R Q R_flat R_steep K1 K1_axis K2 K2_axis Km cyl P zK1 zK1_axis zK2 zK2_axis zKm zcyl rms chi2_dof", want, " ") }
FNR == 1 { file++ }
{ if (file == 1) { va[$1] = $2; sa[$1] = $3; u[$1] = $4 } else { vb[$1] = $2; sb[$1] = $3 } }
END {
    printf "# %s -> %s\n", A, B
    printf "%-10s %14s %14s %12s %12s %8s\n", "quantity", "A", "B", "B-A", "sd", "z"
    bad = 0
    for (i = 1; i <= n; i++) {
        q = want[i]
        if (!(q in va) || !(q in vb) || va[q] == "" || vb[q] == "") continue
        d = vb[q] - va[q]
        if (q ~ /axis/) { while (d > 90) d -= 180; while (d < -90) d += 180 }
        s2 = 0; ok = 1
        if (sa[q] == "inf" || sb[q] == "inf") ok = 0
        else s2 = sa[q] * sa[q] + sb[q] * sb[q]
        if (ok && s2 > 0) { z = d / sqrt(s2); zs = sprintf("%8.2f", z) } else { z = 0; zs = "       -" }
        mark = ""
        if (ok && s2 > 0 && (z > 3 || z < -3)) { mark = "  DIFFERS"; bad = 1 }
        if (!ok) mark = "  (not determined)"
        sds = ok ? sprintf("%12.4g", sqrt(s2)) : sprintf("%12s", "inf")
        printf "%-10s %14.6g %14.6g %12.4g %s %s %s%s\n", q, va[q], vb[q], d, sds, zs,
               u[q], mark
    }
    exit bad
}' "$1" "$2"
