# t_50_bad.sh -- bad input never crashes, hangs or loses data.  Replay: a message
# "lensmat: SOURCE:LINE: ..." on stderr, exit status 2, and the record file holds
# every answer accepted before.  Terminal: explained and asked again (tty_session.py).
# Signals: the record keeps what was accepted.

# bad_case NAME INPUT LINE NACCEPTED PATTERN [BIN]: replay INPUT; expect exit 2, the
# message at LINE matching PATTERN, and the first NACCEPTED answers in the record.
bad_case() {
    name=$1; input=$2; line=$3; nacc=$4; pat=$5; bin=${6:-$BIN}
    printf '%b' "$input" > "$WORK/bad.in"
    (cd "$WORK" && timeout 10 "$bin" bad.rec < bad.in > bad.out 2> bad.err)
    rc=$?
    [ $rc -eq 2 ] || { echo "exit status $rc, want 2"; return 1; }
    grep -q "^lensmat: <stdin>:$line: .*$pat" "$WORK/bad.err" ||
        { echo "message:"; cat "$WORK/bad.err"; return 1; }
    tr -s ' \t' '\n' < "$WORK/bad.in" | sed 's/^input://' | grep -v '^$' | head -n "$nacc" > "$WORK/want"
    grep '^input: ' "$WORK/bad.rec" | sed 's/^input: //' > "$WORK/got"
    diff "$WORK/want" "$WORK/got"
}

D="$GOLDEN/degenerate"
for bin in "$BIN" "$ASAN"; do
t=$( [ "$bin" = "$ASAN" ] && echo " (asan)" )
check "bad: abc as radius$t" bad_case x "$(cat "$D/nonnumeric_radius.in")" 3 2 "radius.*'abc' is not a number" "$bin"
check "bad: abc as object$t" bad_case x "$(cat "$D/nonnumeric_object.in")" 11 10 "'abc' is not a number" "$bin"
check "bad: 1,5 comma decimal$t" bad_case x "$(cat "$D/comma_decimal.in")" 5 4 "'1,5' is not a number" "$bin"
check "bad: 1.2.3$t" bad_case x '25\n1.2.3\n' 2 1 "'1.2.3' is not a number" "$bin"
check "bad: nan index$t" bad_case x '25 1 3 0 nan\n' 1 4 "nan is not a number" "$bin"
check "bad: inf index$t" bad_case x '25\n1\n3\n0\ninf\n' 5 4 "allowed only for a radius" "$bin"
check "bad: inf object$t" bad_case x '25 1 3 0 1.5 n\n-inf\n' 2 6 "allowed only for a radius" "$bin"
check "bad: 1e400$t" bad_case x '25 1 3 0 1.5 n 1e400\n' 1 6 "out of range" "$bin"
check "bad: hex 0x10$t" bad_case x '0x10\n' 1 0 "not a number" "$bin"
check "bad: negative index$t" bad_case x '25\n-1.5\n' 2 1 "must be greater than 0" "$bin"
check "bad: zero index$t" bad_case x '25\n1\n3\n0\n0\n' 5 4 "must be greater than 0" "$bin"
check "bad: negative nearpoint$t" bad_case x '-25\n' 1 0 "must not be negative" "$bin"
check "bad: maybe for y/n$t" bad_case x '25 1 3 0 1.5\nmaybe\n' 2 5 "'maybe': answer y or n" "$bin"
check "bad: number for y/n$t" bad_case x '25 1 3 0 1.5 1\n' 1 5 "answer y or n" "$bin"
check "bad: decreasing location$t" bad_case x "$(cat "$D/location_decreasing.in")" 8 7 "left of the previous surface" "$bin"
check "bad: empty input$t" bad_case x '' 1 0 "end of input while asking for the eye nearpoint" "$bin"
check "bad: eof mid surface$t" bad_case x "$(cat "$D/eof_mid_surface.in")" 4 3 "end of input while asking for the location" "$bin"
check "bad: eof before object$t" bad_case x "$(cat "$D/eof_before_object.in")" 11 10 "end of input while asking for the location of the object plane" "$bin"
check "bad: eof at another object$t" bad_case x '25 1 3 0 1.5 n -10\n' 2 7 "end of input while asking for another object" "$bin"
check "bad: long token$t" bad_case x "$(head -c 400 /dev/zero | tr '\0' 7)\n" 1 0 "longer than 255" "$bin"
check "bad: binary junk$t" bad_case x '\001\002\377\n' 1 0 "not a number" "$bin"
done

# -i FILE names the file in messages
check "bad: -i names the file and line" sh -c "printf '25\n1\nabc\n' > '$WORK/ans.txt' &&
    cd '$WORK' && ! '$BIN' -i ans.txt i.rec > /dev/null 2> i.err &&
    grep -q '^lensmat: ans.txt:3: the radius' i.err"
check "bad: unwritable record file: message, exit 1, no crash" sh -c \
    "'$BIN' /nonexistent/dir/x.rec < /dev/null > /dev/null 2> '$WORK/e';
     [ \$? -eq 1 ] && grep -q 'cannot write the record file' '$WORK/e'"
check "bad: unknown option" sh -c "! '$BIN' --frobnicate x.rec 2> /dev/null"
check "leftover answers warned about, exit 0" sh -c "cd '$WORK' &&
    printf '25 1 3 0 1.5 n -10 n 99\n' | '$BIN' l.rec > /dev/null 2> l.err &&
    grep -q 'ignored' l.err"

# signals: answers accepted before SIGINT/SIGTERM are in the record
sig_case() {
    sig=$1; want=$2
    rm -f "$WORK/fifo"; mkfifo "$WORK/fifo"
    (cd "$WORK" && exec "$BIN" s.rec < fifo > s.out 2> s.err) & pid=$!
    exec 9> "$WORK/fifo"
    printf '25\n1\n3\n' >&9
    sleep 0.5
    kill -"$sig" $pid
    wait $pid; rc=$?
    exec 9>&-
    [ $rc -eq "$want" ] || { echo "exit $rc, want $want"; return 1; }
    [ "$(grep -c '^input: ' "$WORK/s.rec")" -eq 3 ] || { cat "$WORK/s.rec"; return 1; }
    grep -q interrupted "$WORK/s.err"
}
check "SIGINT keeps the record" sig_case INT 130
check "SIGTERM keeps the record" sig_case TERM 143

# a terminal: re-ask with an explanation; Ctrl-D ends cleanly; readline history
if command -v python3 > /dev/null; then
    mkdir -p "$WORK/h1" "$WORK/h2"
    check "tty: typos are explained and asked again" python3 "$TOP/tests/tty_session.py" "$BIN" reask "$WORK/h1"
    check "tty: Ctrl-D ends the session cleanly" python3 "$TOP/tests/tty_session.py" "$BIN" ctrld "$WORK/h2"
fi
check "no readline artefacts without a terminal" sh -c "cd '$WORK' &&
    [ \$('$BIN' n.rec < '$GOLDEN/cases/convex_thin_doc.in' | tr -dc '\\033\\007' | wc -c) -eq 0 ]"
