# t_53_inputs.sh -- no output of a session overwrites a file the session reads
# (src/dialogue/files.c, doc/files.md): an existing OUTFILE that is a lens file, a
# scene or an answers file (the -i forgotten) is refused before it is opened, exit 1,
# the file untouched and the message naming what was probably meant; a file-name
# answer that is the session's record, or an output named earlier, is refused at its
# answer (FILE:LINE, exit 2), under another spelling, a hard link or a symlink; an
# output named in a scene that is an input of the session is refused too.
IN=$WORK/in53
in53_setup() {
    rm -rf "$IN"; mkdir -p "$IN/sub"
    cp "$TOP/doc/triplet.rx" "$IN/lens.rx"
    cp "$TOP/doc/pupil-triplet.rx" "$IN/pt.rx"
    cp "$TOP/scenes/prism.scene" "$TOP/scenes/prism.obj" "$IN/"
    cp "$IN/prism.scene" "$IN/s.scene"
    "$BIN" --to-zmx -i "$IN/pt.rx" "$IN/t.zmx" 2> /dev/null
    sha256sum "$IN/lens.rx" "$IN/pt.rx" "$IN/s.scene" "$IN/t.zmx" > "$IN/sums"
}
untouched() { (cd / && sha256sum -c --quiet "$IN/sums"); }

# OUTFILE is a lens file: --prescription, --to-zmx, --to-thickness, --pupil, --draw
outfile_lens() {   # OPTION FILE WANT
    in53_setup
    (cd "$IN" && "$BIN" "$1" "$2" < /dev/null > out 2> err); rc=$?
    [ $rc -eq 1 ] || { echo "exit $rc"; cat "$IN/err"; return 1; }
    grep -qF -- "$3" "$IN/err" || { cat "$IN/err"; return 1; }
    grep -qF "remove it first" "$IN/err" || { cat "$IN/err"; return 1; }
    untouched
}
check "OUTFILE a prescription, --prescription: refused, did you mean -i" \
    outfile_lens --prescription lens.rx "OUTFILE lens.rx is a lens file (a prescription); did you mean -i lens.rx out.rec?"
check "OUTFILE a prescription, --to-zmx: refused, did you mean -i" \
    outfile_lens --to-zmx lens.rx "did you mean -i lens.rx out.rec?"
check "OUTFILE a prescription, --to-thickness: refused" \
    outfile_lens --to-thickness lens.rx "OUTFILE lens.rx is a lens file (a prescription); did you mean -i lens.rx out.rec?"
check "OUTFILE a .zmx, --to-thickness: refused" \
    outfile_lens --to-thickness t.zmx "OUTFILE t.zmx is a lens file (.zmx); did you mean -i t.zmx out.rec?"
check "OUTFILE a prescription, --pupil: refused, answer it to the question" \
    outfile_lens --pupil pt.rx "did you mean lensmat --pupil out.rec, and pt.rx as the answer"
check "OUTFILE a scene, --trace: refused" \
    outfile_lens --trace s.scene "OUTFILE s.scene is a scene file"
check "OUTFILE a scene under another spelling (./sub/../s.scene): refused" \
    outfile_lens --trace ./sub/../s.scene "is a scene file"
# an answers file (grep input: of a record) named as OUTFILE
outfile_answers() {
    in53_setup
    (cd "$IN" && "$BIN" --example c.rec > /dev/null && grep input: c.rec > ans &&
     cp ans ans.orig && "$BIN" ans < /dev/null > out 2> err); rc=$?
    [ $rc -eq 1 ] && grep -qF "OUTFILE ans is an answers file" "$IN/err" &&
        cmp "$IN/ans" "$IN/ans.orig"
}
check "OUTFILE an answers file: refused, did you mean -i" outfile_answers
# a record is a record: rewritten as before (every golden replay does this too)
outfile_record() {
    in53_setup
    (cd "$IN" && "$BIN" --example c.rec > /dev/null && "$BIN" --example c.rec > /dev/null &&
     cmp c.rec "$GOLDEN/cases/convex_thin_doc.rec" &&
     : > empty.rec && "$BIN" --example empty.rec > /dev/null &&
     cmp empty.rec c.rec)
}
check "OUTFILE an earlier record or an empty file: written as before" outfile_record
# a converter given -i rewrites its own earlier output
outfile_converter_again() {
    in53_setup
    (cd "$IN" && "$BIN" --to-zmx -i pt.rx t.zmx && cp t.zmx t1.zmx &&
     "$BIN" --to-zmx -i pt.rx t.zmx && cmp t.zmx t1.zmx &&
     "$BIN" --to-thickness -i pt.rx t.rx && "$BIN" --to-thickness -i pt.rx t.rx) > /dev/null 2>&1
}
check "--to-zmx -i F OUT twice: the second run rewrites OUT" outfile_converter_again

# a file-name answer that is the record, by another spelling, a hard link, a symlink
answer_is_record() {   # OPTION RECORD ANSWER
    in53_setup
    (cd "$IN" && rm -f r.rec && ln -sf r.rec link.rec && ln -f pt.rx hard.rx &&
     printf '%s\n' "$3" > a.in && "$BIN" "$1" -i a.in "$2" > out 2> err); rc=$?
    [ $rc -eq 2 ] || { echo "exit $rc"; cat "$IN/err"; return 1; }
    grep -q "^lensmat: a.in:[12]: .*is the record file of this session" "$IN/err" ||
        { cat "$IN/err"; return 1; }
    untouched
}
check "--pupil r.rec answering r.rec: refused at the answer" answer_is_record --pupil r.rec r.rec
check "--pupil r.rec answering ./sub/../r.rec: refused" answer_is_record --pupil r.rec ./sub/../r.rec
check "--pupil r.rec answering a symlink to r.rec: refused" answer_is_record --pupil r.rec link.rec
check "--draw r.rec answering r.rec: refused" answer_is_record --draw r.rec r.rec
check "--trace r.rec answering r.rec as the scene: refused" answer_is_record --trace r.rec "scene
r.rec"
# a hard link of the record's file: pupil's OUTFILE is a new hard link of an old record
answer_hard_link() {
    in53_setup
    (cd "$IN" && "$BIN" --example old.rec > /dev/null && ln -f old.rec r.rec &&
     printf 'old.rec\n' > a.in && "$BIN" --pupil -i a.in r.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] && grep -q "a.in:1: .*old.rec is the record file of this session" "$IN/err"
}
check "--pupil answering a hard link of its record: refused" answer_hard_link

# a scene whose output is a file the session read (its lens file given earlier is
# the mesh here): the scene's own output checks and the session's
scene_output_is_input() {
    in53_setup
    (cd "$IN" && sed 's/^output hits .*/output hits a.in/' prism.scene > o.scene &&
     printf 'scene\no.scene\n' > a.in && "$BIN" --trace -i a.in r.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] && grep -q "a.in is the file the answers are read from" "$IN/err" &&
        [ "$(sed -n 2p "$IN/a.in")" = o.scene ]
}
check "--trace: a scene whose output is the answers file is refused" scene_output_is_input
scene_output_is_mesh_of_session() {
    in53_setup
    (cd "$IN" && sed 's/^output hits .*/output hits r.rec/' prism.scene > o.scene &&
     printf 'scene\no.scene\n' > a.in && "$BIN" --trace -i a.in r.rec > out 2> err); rc=$?
    [ $rc -eq 2 ] && grep -q "r.rec is the record file of this session" "$IN/err"
}
check "--trace: a scene whose output is the record is refused" scene_output_is_mesh_of_session
