#!/usr/bin/env python3
"""tty_pupil.py BIN TOP HOME -- lensmat --pupil on a pseudo-terminal: a lens file that
is not there, a stop out of range, a sampling that is not one and a count too large
are each explained and asked again; the session then completes and the record holds
only the accepted answers.  Exit 0 when every check holds."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptydrive import drive

def main():
    bin_, top, home = sys.argv[1], sys.argv[2], sys.argv[3]
    rec = os.path.join(home, "p.rec")
    lens = os.path.join(top, "doc", "triplet.rx")
    keys = [b"nosuch.rx\n", lens.encode() + b"\n", b"9\n", b"4\n", b"epd\n", b"10\n",
            b"1\n", b"0\n", b"square\n", b"hex\n", b"99\n", b"2\n", b"n\n"]
    rc, out = drive([bin_, "--pupil", rec], keys, home=home, timeout=20, quiet=0.15)
    bad = []
    for want in ["nosuch.rx: cannot be read", "'9': give a surface number from 1 to 6",
                 "the pupil sampling: 'square' is not one of the choices", "'99': give a whole number from 1 to 32",
                 "spot: 19 rays, 0 vignetted", "Output was written to file"]:
        if want not in out:
            bad.append("missing: " + want)
    if rc != 0:
        bad.append("exit %d" % rc)
    try:
        ins = [l for l in open(rec).read().splitlines() if l.startswith("input:")]
    except OSError:
        ins = []
    if ins != ["input: " + lens, "input: 4", "input: epd", "input: 10", "input: 1",
               "input: 0", "input: hex", "input: 2", "input: n"]:
        bad.append("record answers: %r" % ins)
    if bad:
        print("\n".join(bad))
        print(out[-3000:])
        return 1
    return 0

sys.exit(main())
