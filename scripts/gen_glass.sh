#!/bin/sh
# gen_glass.sh IN OUT -- turn data/glass.txt (format at its top) into a C header: a
# static table px_glass_table[] of names, models, ranges, published nd/Vd (as the
# source prints them: strings, so a test knows how many digits were printed) and
# coefficients.  The catalogue stays data; this only compiles it in.
set -e
in=$1; out=$2
awk '
BEGIN { n = 0 }
/^[ \t]*#/ || /^[ \t]*$/ { next }
{
    if (NF < 7) { bad(NR, "expected NAME MODEL LMIN LMAX ND VD COEFFICIENTS...") }
    m = $2
    if (m == "sellmeier") model = "PX_GLASS_SELLMEIER"
    else if (m == "sellmeier-l") model = "PX_GLASS_SELLMEIER_L"
    else if (m == "const") model = "PX_GLASS_CONST"
    else bad(NR, "unknown model " m)
    nc = NF - 6
    if (m != "const" && nc % 2) bad(NR, "coefficients must come in pairs")
    if (m == "const" && nc != 1) bad(NR, "const takes one coefficient")
    if (nc > 8) bad(NR, "at most 8 coefficients")
    if ($1 ~ /[@\/"\\]/) bad(NR, "a name holds no @, / or quote")
    for (i = 3; i <= NF; i++)
        if (!(i == 5 || i == 6) || $i != "-")
            if ($i !~ /^[-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$/) bad(NR, "not a number: " $i)
    if (!($3 + 0 < $4 + 0)) bad(NR, "LMIN must be below LMAX")
    c = ""
    for (i = 7; i <= NF; i++) c = c (i > 7 ? ", " : "") $i
    rows[n++] = sprintf("    {\"%s\", %s, %s, %s, \"%s\", \"%s\", %d, {%s}},", \
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
}' "$in" > "$out.tmp"
mv "$out.tmp" "$out"
