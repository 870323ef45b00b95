#!/bin/sh
# gen_prompts.sh NAME IN OUT -- turn prompts/NAME.txt into a C header: an enum of
# NAME_KEY indices and a static table NAME_prompts[] of the texts.  The texts stay
# data under prompts/; this only makes them reachable without a file at run time.
set -e
name=$1; in=$2; out=$3
awk -v name="$name" '
BEGIN { n = 0 }
function flush() { if (key != "") { keys[n] = key; vals[n] = val; n++ } key = "" }
/^[ \t]*#/ || /^[ \t]*$/ { next }
/^[A-Za-z_][A-Za-z0-9_]*[ \t]/ {
    flush(); key = toupper(name "_" $1); val = $0; sub(/^[^ \t]+[ \t]+/, "", val); next
}
/^[ \t]+"/ { line = $0; sub(/^[ \t]+/, "", line); val = val "\n    " line; next }
{ printf "%s:%d: cannot parse this line\n", FILENAME, NR > "/dev/stderr"; bad = 1; exit 1 }
END {
    if (bad) exit 1
    flush()
    up = toupper(name)
    print "/* generated from prompts/" name ".txt by scripts/gen_prompts.sh: do not edit */"
    print "enum {"
    for (i = 0; i < n; i++) print "    " keys[i] ","
    print "    " up "_NPROMPTS"
    print "};"
    print "static const char *const " name "_prompts[" up "_NPROMPTS] = {"
    for (i = 0; i < n; i++) print "    [" keys[i] "] = (" vals[i] "),"
    print "};"
}' "$in" > "$out.tmp"
mv "$out.tmp" "$out"
