# t_15_cli.sh -- the command line: usage text, --help, --version, --example, one
# dialogue option at a time, and what ./lensmat links (libc, libm, readline only).
check "no arguments: the original usage text plus a pointer to --help, exit 1 (no OUTFILE)" sh -c \
    "'$BIN' > '$WORK/u'; [ \$? -eq 1 ] && head -n 17 '$WORK/u' | cmp - '$GOLDEN/degenerate/usage_no_args.stdout' &&
     [ \$(wc -l < '$WORK/u') -eq 18 ] && tail -n 1 '$WORK/u' | grep -q -- --help"
check "--original alone: the original usage text exactly" sh -c \
    "'$BIN' --original > '$WORK/uo'; [ \$? -eq 1 ] && cmp '$WORK/uo' '$GOLDEN/degenerate/usage_no_args.stdout'"
check "--help lists the classic dialogue and the options" sh -c \
    "'$BIN' --help > '$WORK/h' && grep -q -- '--classic' '$WORK/h' &&
     grep -q -- '--original' '$WORK/h' && grep -q -- '--input' '$WORK/h'"
check "--version" sh -c "'$BIN' --version | grep -Eq '^lensmat [0-9]'"
check "--example replays the section-13 example" sh -c \
    "cd '$WORK' && '$BIN' --example --original ex.rec > ex.out &&
     cmp ex.rec '$GOLDEN/cases/convex_thin_doc.rec'"
check "--classic is the default dialogue" sh -c \
    "cd '$WORK' && '$BIN' --classic c1.rec < '$GOLDEN/cases/doublet_4surf.in' > /dev/null &&
     '$BIN' c2.rec < '$GOLDEN/cases/doublet_4surf.in' > /dev/null && cmp c1.rec c2.rec"
check "missing OUTFILE is an error" sh -c "! '$BIN' --classic < /dev/null 2> /dev/null"
check "two OUTFILEs are an error" sh -c "! '$BIN' a b < /dev/null 2> /dev/null"
check "lensmat links only libc, libm, readline" sh -c \
    "ldd '$BIN' | awk '{print \$1}' | grep -Ev '^(linux-vdso|/lib64/ld-linux|libc|libm|libreadline|libtinfo)' | grep . && exit 1; exit 0"
