# t_40_diff.sh -- differential test: lensmat --original against the transcribed
# original program (built from ../shared/original-lensmat) on 300 random valid
# prescriptions from its own gen_cases.py (plus 100 with thin lenses and water on the
# left), byte for byte; the default mode must agree on every line but the nodal planes.
# Also: the grep'd record of each replays to the same record.

diff_case() {
    in=$1; d=$WORK/d; rm -rf "$d"; mkdir -p "$d"; cd "$d" || return 1
    "$ORIG" x.rec < "$in" > o.out 2>&1 && cp x.rec o.rec || return 1
    "$BIN" --original x.rec < "$in" > n.out && cp x.rec n.rec || return 1
    "$BIN" x.rec < "$in" > m.out || return 1
    cd "$TOP" || return 1
    cmp "$d/o.out" "$d/n.out" && cmp "$d/o.rec" "$d/n.rec" || return 1
    # default mode: only nodal-plane lines may differ
    ! diff "$d/o.rec" "$d/x.rec" | grep '^[<>]' | grep -qv '^[<>] Nodal plane [12], z= '
}

if have_shared && command -v python3 > /dev/null; then
    gen=$SHARED/original-lensmat/gen_cases.py
    python3 "$gen" 11 300 "$WORK/gen" > /dev/null 2>&1
    python3 "$gen" 12 100 "$WORK/gen" --prefix thin --thin-prob 0.4 > /dev/null 2>&1
    n=0; bad=0
    for f in "$WORK"/gen/*.in; do
        n=$((n + 1))
        if diff_case "$f" > /dev/null 2>&1; then pass "diff $(basename "$f")"
        else fail "diff $(basename "$f") (against the original program)"; bad=$((bad + 1)); fi
    done
    [ -n "$VERBOSE" ] && echo "differential: $n cases, $bad differ"
else
    fail "differential test: ../shared/original-lensmat or python3 missing"
fi
