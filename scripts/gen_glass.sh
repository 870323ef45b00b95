#!/bin/sh
# gen_glass.sh IN OUT -- turn data/glass.txt (format at its top) into a C header: a
# static table px_glass_table[] of names, models, ranges, published nd/Vd (as the
# source prints them: strings, so a test knows how many digits were printed) and
# coefficients; px_tau_table[] of the internal-transmittance tables (NAME tau
# THICKNESS L T ...); and px_former_table[] of former glass names (OLD former NEW
# WHY).  The catalogue stays data; this only compiles it in.
set -e
in=$1; out=$2
awk '
BEGIN { n = 0; nt = 0; nf = 0 }
/^[ \t]*#/ || /^[ \t]*$/ { next }
$2 == "k" {      # an extinction-coefficient table: thickness 0 in the C table
    $0 = $1 " tau 0 " substr($0, index($0, " k ") + 3)
}
$2 == "former" {   # NAME former SUCCESSOR WHY...: an old glass name and its successor
    if (NF < 4) bad(NR, "expected OLDNAME former NEWNAME WHY...")
    if (!($3 in known)) bad(NR, "former: " $3 " is not a glass of the catalogue (above)")
    if ($1 in known) bad(NR, "former: " $1 " is itself a glass of the catalogue")
    why = $0; sub(/^[^ \t]+[ \t]+former[ \t]+[^ \t]+[ \t]+/, "", why)
    gsub(/\\/, "\\\\", why); gsub(/"/, "\\\"", why)
    formers[nf++] = sprintf("    {\"%s\", \"%s\", \"%s\"},", $1, $3, why)
    next
}
$2 == "tau" {
    if (!($1 in known)) bad(NR, "tau: " $1 " is not a glass of the catalogue (above)")
    if (NF < 6 || (NF - 3) % 2) bad(NR, "expected NAME tau THICKNESS L1 T1 L2 T2 ... or NAME k L1 K1 ...")
    if ((NF - 3) / 2 > 40) bad(NR, "at most 40 points")
    for (i = 3; i <= NF; i++)
        if ($i !~ /^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$/) bad(NR, "not a number: " $i)
    if (!($3 + 0 > 0) && $3 != "0") bad(NR, "the thickness must be positive")
    l = ""; t = ""; prev = 0
    for (i = 4; i < NF; i += 2) {
        if (!($i + 0 > prev)) bad(NR, "wavelengths must ascend: " $i)
        if ($3 != "0" && $(i + 1) + 0 > 1) bad(NR, "a transmittance above 1: " $(i + 1))
        prev = $i + 0
        l = l (i > 4 ? ", " : "") $i
        t = t (i > 4 ? ", " : "") $(i + 1)
    }
    taus[nt++] = sprintf("    {\"%s\", %s, %d, {%s}, {%s}},", $1, $3, (NF - 3) / 2, l, t)
    next
}
{
    if (NF < 7) { bad(NR, "expected NAME MODEL LMIN LMAX ND VD COEFFICIENTS...") }
    m = $2
    if (m == "sellmeier") model = "PX_GLASS_SELLMEIER"
    else if (m == "sellmeier-l") model = "PX_GLASS_SELLMEIER_L"
    else if (m == "const") model = "PX_GLASS_CONST"
    else if (m == "schott") model = "PX_GLASS_AGF + 1"
    else bad(NR, "unknown model " m)
    nc = NF - 6
    if (m != "const" && nc % 2) bad(NR, "coefficients must come in pairs")
    if (m == "const" && nc != 1) bad(NR, "const takes one coefficient")
    if (nc > 10) bad(NR, "at most 10 coefficients")
    if ($1 ~ /[@\/"\\]/) bad(NR, "a name holds no @, / or quote")
    for (i = 3; i <= NF; i++)
        if (!(i == 5 || i == 6) || $i != "-")
            if ($i !~ /^[-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$/) bad(NR, "not a number: " $i)
    if (!($3 + 0 < $4 + 0)) bad(NR, "LMIN must be below LMAX")
    known[$1] = 1
    c = ""
    for (i = 7; i <= NF; i++) c = c (i > 7 ? ", " : "") $i
    rows[n++] = sprintf("    {\"%s\", %s, %s, %s, \"%s\", \"%s\", %d, {%s}, \"LENSMAT\", \"\"},", \
                        $1, model, $3, $4, $5, $6, nc, c)
}
function bad(line, msg) {
    printf "%s:%d: %s\n", FILENAME, line, msg > "/dev/stderr"; failed = 1; exit 1
}
END {
    if (failed) exit 1
    print "/* generated from data/glass.txt by scripts/gen_glass.sh: do not edit */"
    print "static const px_glass_rec px_glass_table[] = {"
    for (i = 0; i < n; i++) print rows[i]
    print "};"
    print "static const px_tau_rec px_tau_table[] = {"
    for (i = 0; i < nt; i++) print taus[i]
    if (!nt) print "    {\"\", 1, 0, {0}, {0}},"
    print "};"
    print "#define PX_NTAU " nt
    print "static const struct { const char *old, *now, *why; } px_former_table[] = {"
    for (i = 0; i < nf; i++) print formers[i]
    if (!nf) print "    {\"\", \"\", \"\"},"
    print "};"
    print "#define PX_NFORMER " nf
}' "$in" > "$out.tmp"
mv "$out.tmp" "$out"
