# t_80_install.sh -- make install into a temporary DESTDIR and PREFIX, runs of the
# installed lensmat from another folder (its modules found from its own location,
# EXEDIR/../lib/lensmat, not from the build tree), the man page, make uninstall.
I=$WORK/inst; DEST=$I/dest; PFX=/opt/lm
install_tree() {
    rm -rf "$I"; mkdir -p "$I/elsewhere"
    make -s -C "$TOP" install DESTDIR="$DEST" PREFIX="$PFX" > "$I/make.log" 2>&1 ||
        { tail "$I/make.log"; return 1; }
    for f in bin/lensmat lib/lensmat/lensmat-trace.so lib/lensmat/lensmat-fit.so \
             share/man/man1/lensmat.1 share/doc/lensmat/README.md; do
        [ -f "$DEST$PFX/$f" ] || { echo "not installed: $f"; return 1; }
    done
    [ -x "$DEST$PFX/bin/lensmat" ]
}
installed_runs() (   # a subshell: its cd stays inside
    B=$DEST$PFX/bin/lensmat
    cd "$I/elsewhere" || return 1
    env -u LENSMAT_LIBDIR "$B" --example c.rec > c.out && cmp c.rec "$GOLDEN/cases/convex_thin_doc.rec" || return 1
    # a trace session loads its module from the installed tree
    env -u LENSMAT_LIBDIR LD_DEBUG=files "$B" --trace --example t.rec > t.out 2> t.ld || return 1
    grep -q "$DEST$PFX/bin/../lib/lensmat/lensmat-trace.so" t.ld || { echo "trace module not from the install"; return 1; }
    grep -q "$TOP/build" t.ld && { echo "the build tree was used"; return 1; }
    [ "$(grep -c 'meets the paraxial image to' t.rec)" -eq 2 ] || return 1
    env -u LENSMAT_LIBDIR "$B" --fit --example f.rec > f.out && grep -q 'Power P = -C' f.rec || return 1
    cd "$TOP"
)
man_page() {
    command -v man > /dev/null || return 0
    MANWIDTH=80 man -l "$DEST$PFX/share/man/man1/lensmat.1" 2> "$I/man.err" > "$I/man.txt" || return 1
    grep -q 'LENSMAT_LIBDIR' "$I/man.txt" && grep -q -- '--to-prescription' "$I/man.txt"
}
uninstall_tree() {
    make -s -C "$TOP" uninstall DESTDIR="$DEST" PREFIX="$PFX" > /dev/null 2>&1 || return 1
    left=$(find "$DEST" -type f)
    [ -z "$left" ] || { echo "left after uninstall: $left"; return 1; }
}
check "make install DESTDIR PREFIX: binary, modules, man page, README" install_tree
check "installed lensmat runs from another folder; --trace and --fit load installed modules" installed_runs
# the examples' data are installed (PREFIX/share/lensmat) and found from any folder
installed_examples() (
    B=$DEST$PFX/bin/lensmat
    cd "$I/elsewhere" || return 1
    for f in doc/triplet.rx doc/pupil-triplet.rx golden/rig/example.rig; do
        cmp "$DEST$PFX/share/lensmat/$f" "$TOP/$f" || return 1; done
    env -u LENSMAT_LIBDIR "$B" --pupil --example p.rec > p.out 2> p.err || { cat p.err; return 1; }
    grep -q "^input: $DEST$PFX/bin/../share/lensmat/doc/pupil-triplet.rx" p.rec || return 1
    grep -q 'efl 50' p.rec || { head p.rec; return 1; }
    env -u LENSMAT_LIBDIR "$B" --rig --example r.rec > r.out 2> r.err || { cat r.err; return 1; }
    grep -q "share/lensmat/golden/rig/example.rig" r.rec || return 1
    env -u LENSMAT_LIBDIR "$B" --draw --example d.rec > d.out 2> d.err || { cat d.err; return 1; }
    [ -s triplet-layout.png ] && [ -s triplet-layout.svg ] || return 1
    # the recorded answers replay to the same record, here too
    grep input: p.rec > p.in && env -u LENSMAT_LIBDIR "$B" --pupil -i p.in p2.rec > /dev/null &&
        cmp p.rec p2.rec
)
check "the installed --pupil, --rig and --draw examples run from another folder" installed_examples
check "the installed man page renders" man_page
check "make uninstall removes every installed file" uninstall_tree
