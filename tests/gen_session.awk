# gen_session.awk -- a random valid classic session with full-precision numbers
# (17 significant digits, beyond what the original's %g echo keeps), for replay
# tests.  Usage: awk -v seed=N -f tests/gen_session.awk
BEGIN {
    srand(seed)
    printf "%.17g\n%.17g\n", 10 + 30 * rand(), (rand() < 0.5) ? 1 : 1 + rand() / 3
    z = 10 * rand() - 5; ns = 1 + int(6 * rand())
    for (i = 1; i <= ns; i++) {
        r = (2 + 40 * rand()) * ((rand() < 0.5) ? -1 : 1)
        printf "%.17g\n%.17g\n%.17g\n%s\n", r, z, 1 + rand(), (i < ns) ? "y" : "n"
        z += 0.05 + 5 * rand()
    }
    no = 1 + int(3 * rand())
    for (i = 1; i <= no; i++) printf "%.17g\n%s\n", -200 * rand() - 20, (i < no) ? "y" : "n"
}
