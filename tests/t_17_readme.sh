# t_17_readme.sh -- every command README.md and doc/*.md show is run and checked, by
# the convention doc/hacking.md's "README's examples" paragraph sets out:
# - a block fenced ```sh is a script: its lines run in order with `sh -e`;
# - a block fenced ```console holds `$ COMMAND` lines, each followed by the output
#   it shows (stdout and stderr, trailing blanks ignored; a line `...` stands for any
#   number of lines); the command must exit 0 unless its line ends `# exit N`;
# - every block runs, top to bottom, in one scratch folder that mirrors the top of a
#   built tree (a link to every top-level entry: ./lensmat, scenes/, golden/, ...),
#   so earlier blocks' files are there for later ones; lensmat is not on PATH, as on
#   a fresh machine, so a bare `lensmat` fails;
# - a line `make TARGET...` is not run (make check would recurse); its targets must
#   exist (make -n succeeds in the tree).
# Other blocks (``` alone, ```text) are file contents and screens, not commands.

RM_DIR=$WORK/readme
rm -rf "$RM_DIR"
mkdir -p "$RM_DIR/blocks" "$RM_DIR/run"
for e in "$TOP"/* "$TOP"/.[!.]*; do
    [ -e "$e" ] || continue
    case ${e##*/} in .git|readme) continue ;; esac
    ln -s "$e" "$RM_DIR/run/${e##*/}"
done

# The documents whose blocks run: README.md, then the doc/*.md files in the order
# README links them, then any other doc/*.md (alphabetical).  All share one scratch
# folder, so a later document may use the files an earlier one's blocks wrote.
RM_DOCS=README.md
for d in $(grep -o '](doc/[A-Za-z0-9_-]*\.md)' "$TOP/README.md" | sed 's/^](//; s/)$//') \
         $(cd "$TOP" && ls doc/*.md 2>/dev/null); do
    case " $RM_DOCS " in *" $d "*) ;; *) [ -f "$TOP/$d" ] && RM_DOCS="$RM_DOCS $d" ;; esac
done

# Cut each document into blocks: blocks/KKK.NNNNN.sh or .console, KKK the document's
# place in RM_DOCS, NNNNN the line of the fence; blocks/KKK.name holds its name.
k=0
for d in $RM_DOCS; do
    k=$((k + 1)); kk=$(printf '%03d' "$k")
    awk -v dir="$RM_DIR/blocks" -v kk="$kk" '
        !inb && /^```(sh|console)[ \t]*$/ {
            inb = 1; kind = substr($0, 4); sub(/[ \t]+$/, "", kind)
            f = sprintf("%s/%s.%05d.%s", dir, kk, NR, kind); printf "" > f; next }
        !inb && /^```/ { other = !other; next }
        inb && /^```/ { inb = 0; close(f); next }
        inb { print > f }' "$TOP/$d"
    printf '%s\n' "$d" > "$RM_DIR/docname.$kk"
done

# PATH without any folder that holds a lensmat (an installed one must not hide a
# bare `lensmat` in README)
RM_PATH=$(printf '%s' "$PATH" | tr ':' '\n' | while read -r d; do
    [ -n "$d" ] && [ ! -e "$d/lensmat" ] && printf '%s:' "$d"; done)
RM_PATH=${RM_PATH%:}

# readme_make ARGS: the make line exists as targets of the tree's Makefile
cat > "$RM_DIR/make.sh" <<'EOF'
readme_make() {
    if ! make -n -C "$README_TOP" "$@" > /dev/null 2>&1; then
        echo "README: make $*: not a target of the Makefile" >&2; exit 1
    fi
}
EOF

# readme_match EXPECTED ACTUAL: ACTUAL has EXPECTED's lines in order, `...` any lines
readme_match() {
    awk 'NR == FNR { sub(/[ \t]+$/, ""); want[++nw] = $0; next }
         { sub(/[ \t]+$/, ""); got[++ng] = $0 }
         END {
             g = 1; skip = 0
             for (w = 1; w <= nw; w++) {
                 if (want[w] == "...") { skip = 1; continue }
                 if (skip) { while (g <= ng && got[g] != want[w]) g++ }
                 if (g > ng || got[g] != want[w]) {
                     printf "README shows: %s\n", want[w]
                     printf "the command printed %s\n", g > ng ? "nothing more" : "instead: " got[g]
                     exit 1 }
                 g++; skip = 0
             }
             if (!skip && g <= ng) { printf "README does not show: %s\n", got[g]; exit 1 }
         }' "$1" "$2"
}

for b in "$RM_DIR"/blocks/*; do
    [ -e "$b" ] || continue
    n=$(basename "$b"); kk=${n%%.*}; rest=${n#*.}
    line=$(expr "${rest%%.*}" + 0); kind=${rest#*.}
    doc=$(cat "$RM_DIR/docname.$kk")
    if [ "$kind" = sh ]; then
        { cat "$RM_DIR/make.sh"
          sed 's/^[ \t]*make\([ \t]\)/readme_make\1/; s/^[ \t]*make$/readme_make/' "$b"; } \
            > "$RM_DIR/block.sh"
        check "$doc:$line: the sh block runs" sh -c "cd '$RM_DIR/run' &&
            PATH='$RM_PATH' README_TOP='$TOP' sh -e '$RM_DIR/block.sh'"
    else
        # one command and its shown output at a time
        awk -v dir="$RM_DIR" '
            /^\$ / { if (f) close(f); k++; f = sprintf("%s/cmd%03d", dir, k)
                     print substr($0, 3) > f; close(f); f = sprintf("%s/out%03d", dir, k)
                     printf "" > f; next }
            f { print > f }' "$b"
        for c in "$RM_DIR"/cmd*; do
            [ -e "$c" ] || { fail "$doc:$line: a console block without a \$ command"; break; }
            k=${c##*/cmd}; cmd=$(cat "$c")
            disp=$(printf '%s' "$cmd" | tr '\\' '/' | cut -c1-70)   # echo-safe name
            want=0
            case $cmd in *"# exit "[0-9]*) want=${cmd##*# exit } ;; esac
            (cd "$RM_DIR/run" && PATH=$RM_PATH sh -c "$cmd" > "$RM_DIR/got" 2>&1); rc=$?
            if [ "$rc" -ne "$want" ]; then
                fail "$doc:$line: \$ $disp: exit status $rc, README expects $want"
                sed 's/^/    /' "$RM_DIR/got" | head -20
            elif readme_match "$RM_DIR/out$k" "$RM_DIR/got" > "$RM_DIR/why"; then
                pass "$doc:$line: \$ $disp"
            else
                fail "$doc:$line: \$ $disp: output differs"
                sed 's/^/    /' "$RM_DIR/why"
            fi
        done
        rm -f "$RM_DIR"/cmd* "$RM_DIR"/out*
    fi
done
check "README.md has blocks to run" sh -c "ls '$RM_DIR'/blocks/*.sh > /dev/null 2>&1"

# The checker itself must catch what it is for (on a scratch README, same rules)
printf 'a\n...\nc\n' > "$RM_DIR/w1"; printf 'a\nb\nb2\nc\n' > "$RM_DIR/g1"
check "readme test: ... matches any lines" readme_match "$RM_DIR/w1" "$RM_DIR/g1"
printf 'a\nc\n' > "$RM_DIR/w2"
if readme_match "$RM_DIR/w2" "$RM_DIR/g1" > /dev/null; then fail "readme test: extra output not caught"
else pass "readme test: extra output caught"; fi
check "readme test: bare lensmat is not on PATH" sh -c "cd '$RM_DIR/run' && PATH='$RM_PATH' && ! command -v lensmat"

# README stays what a first hour needs; the reference is in doc/, and every link resolves
check "README.md is at most 400 lines" sh -c "[ \$(wc -l < '$TOP/README.md') -le 400 ]"
rm_links() {
    for d in $RM_DOCS; do
        dir=$(dirname "$TOP/$d")
        for l in $(grep -o '](\([A-Za-z0-9_./-]*\))' "$TOP/$d" | sed 's/^](//; s/)$//'); do
            case $l in http*|\#*) continue ;; esac
            [ -e "$dir/${l%%#*}" ] || { echo "$d links $l: no such file"; return 1; }
        done
    done
}
check "README.md and doc/*.md: every relative link names a file" rm_links
check "README.md links doc/ documents" sh -c "[ \$(echo $RM_DOCS | wc -w) -gt 5 ]"
