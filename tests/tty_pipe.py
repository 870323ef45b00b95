#!/usr/bin/env python3
"""tty_pipe.py BIN DIR -- lensmat with a person at the keyboard (standard input and
stderr on a pseudo-terminal) but standard output piped into a file, as in
`lensmat x.rec | tee log`: the session must stay interactive (a typo is explained
and asked again, not the end of a replay), the prompts must reach the pipe, and
readline's echo and editing must stay off it.  Exit 0 when every check holds."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptydrive import drive

def main():
    bin_, d = sys.argv[1], sys.argv[2]
    rec, log = os.path.join(d, "p.rec"), os.path.join(d, "p.log")
    keys = [b"abc\n", b"25\n", b"1\n", b"3\n", b"0\n", b"1.5\n", b"n\n", b"-10\n", b"n\n"]
    rc, screen = drive(["/bin/sh", "-c", 'exec "$0" "$1" | cat > "$2"', bin_, rec, log],
                       keys, home=d, timeout=20, quiet=0.2)
    bad = []
    if rc != 0:
        bad.append("exit status %d, want 0" % rc)
    if "'abc' is not a number; please answer again" not in screen:
        bad.append("the typo was not explained and asked again on the terminal")
    out = open(log, "rb").read()
    if b"Enter the eye nearpoint" not in out or b"Image plane" not in out:
        bad.append("the prompts and results did not reach the pipe")
    if b"\x1b" in out or b"\x07" in out:
        bad.append("terminal control bytes in the piped output")
    ins = [l[7:].strip() for l in open(rec) if l.startswith("input: ")]
    if ins != ["25", "1", "3", "0", "1.5", "n", "-10", "n"]:
        bad.append("record answers %r" % ins)
    for b in bad:
        print(b)
    if bad:
        print("---- screen ----\n" + screen[-2000:] + "\n---- pipe ----\n" +
              out[-1500:].decode(errors="replace"))
    return 1 if bad else 0

sys.exit(main())
