#!/usr/bin/env python3
"""tty_session.py BIN MODE HOME -- drive lensmat on a pseudo-terminal, as a person at a
keyboard would, and check what a person would see.  MODE:
  reask  a typo at every kind of question is explained and asked again; the session
         then completes and the record holds only the accepted answers
  ctrld  Ctrl-D at a question ends the session cleanly (exit 0), record kept
Exit 0 when every check holds; prints what failed otherwise."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptydrive import drive

def run(bin_, args, keys, home, timeout=10):
    return drive([bin_] + args, keys, home=home, timeout=timeout, quiet=0.15)

def main():
    bin_, mode, home = sys.argv[1], sys.argv[2], sys.argv[3]
    rec = os.path.join(home, "t.rec")
    bad = []
    if mode == "reask":
        keys = [b"abc\n", b"25\n", b"-1\n", b"1\n", b"3\n", b"0\n", b"1,5\n", b"1.5\n",
                b"maybe\n", b"y\n", b"-3\n", b"-1\n", b"0\n", b"1\n", b"n\n",
                b"nan\n", b"-2\n", b"n\n"]
        rc, out = run(bin_, [rec], keys, home)
        for want in ["'abc' is not a number; please answer again",
                     "'-1' must be greater than 0; please answer again",
                     "'1,5' is not a number; please answer again",
                     "'maybe': answer y or n; please answer again",
                     "lies left of the previous surface",
                     "nan is not a number",
                     "Image plane, z= -6", "Output was written to file"]:
            if want not in out:
                bad.append("screen lacks %r" % want)
        if rc != 0:
            bad.append("exit status %d, want 0" % rc)
        ins = [l[7:].strip() for l in open(rec) if l.startswith("input: ")]
        if ins != ["25", "1", "3", "0", "1.5", "y", "-3", "0", "1", "n", "-2", "n"]:
            bad.append("record answers %r" % ins)
        hist = open(os.path.join(home, ".lensmat_history")).read().split()
        if "1.5" not in hist or "-2" not in hist:
            bad.append("history lacks the answers: %r" % hist)
    else:
        rc, out = run(bin_, [rec], [b"25\n", b"1\n", b"3\n", b"\x04"], home)
        if rc != 0:
            bad.append("Ctrl-D: exit status %d, want 0" % rc)
        if "session ended" not in out:
            bad.append("Ctrl-D: no 'session ended' message")
        ins = [l[7:].strip() for l in open(rec) if l.startswith("input: ")]
        if ins != ["25", "1", "3"]:
            bad.append("Ctrl-D: record answers %r" % ins)
    for b in bad:
        print(b)
    if bad:
        print("---- screen ----\n" + out[-3000:])
    return 1 if bad else 0

sys.exit(main())
