# t_20_golden.sh -- the classic dialogue against the original program's reference
# runs in golden/ (copied from ../shared/reference/lensmat).  --original: stdout and
# record byte for byte.  Default mode: the same, except the two nodal-plane lines of
# systems whose outer media differ (the original's nodal planes are wrong there).

# media_differ FILE.in: exit 0 if the index left of the first surface differs from
# the index right of the last one (tokens: nearpoint n0 {r z n yn}... objects)
media_differ() {
    tr -s ' \t\r' '\n' < "$1" | awk 'NF { t[++k] = $1 }
        END { n0 = t[2]; i = 3; do { n = t[i + 2]; yn = t[i + 3]; i += 4 } while (yn == "y")
              exit (n0 + 0 == n + 0) }'
}

# golden_run BIN MODE DIR NAME: run one case in $WORK/g, compare with DIR/NAME.*
golden_run() {
    bin=$1; mode=$2; dir=$3; name=$4
    rm -rf "$WORK/g"; mkdir -p "$WORK/g"
    (cd "$WORK/g" && "$bin" $mode "$name.rec" < "$dir/$name.in" > "$name.stdout") || return 1
    if [ "$mode" = "--original" ] || ! media_differ "$dir/$name.in"; then
        cmp "$WORK/g/$name.stdout" "$dir/$name.stdout" && cmp "$WORK/g/$name.rec" "$dir/$name.rec"
        return
    fi
    for f in stdout rec; do
        diff "$dir/$name.$f" "$WORK/g/$name.$f" > "$WORK/g/d" && return 1  # must differ
        grep '^[<>]' "$WORK/g/d" | grep -v '^[<>] Nodal plane [12], z= ' && return 1
        [ "$(grep -c '^[<>]' "$WORK/g/d")" -le 4 ] || return 1
    done
    return 0
}

for dir in "$GOLDEN/cases" "$GOLDEN/random_sample"; do
    for f in "$dir"/*.in; do
        name=$(basename "$f" .in)
        for bin in "$BIN" "$ASAN"; do
            tag=$( [ "$bin" = "$ASAN" ] && echo asan || echo opt )
            check "golden original $tag $name" golden_run "$bin" --original "$dir" "$name"
            check "golden default $tag $name" golden_run "$bin" "" "$dir" "$name"
        done
    done
done
check "golden all_on_one_line" golden_run "$BIN" "" "$GOLDEN/degenerate" all_on_one_line
check "golden replay_sed_stripped" golden_run "$BIN" --original "$GOLDEN/degenerate" \
    replay_sed_stripped
