#!/usr/bin/env python3
"""calc_tty.py BIN HOME -- the calculation dialogues' checks of answers that do not go
together, on a pseudo-terminal: each bad group is explained (why, and what is asked
again), asked again, the session completes with exit 0, and the record holds only
the accepted answers (its grep'd answers are exactly those typed and accepted,
and replay to the same record).
Prints one line per failed check; exit 0 when all hold."""
import os, subprocess, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptydrive import drive

CASES = [
    # name, option, typed lines, screen must show, accepted answers in the record
    ("telescope erector with Galileo", "--telescope",
     ["cm", "100", "-5", "40", "5", "40"],
     ["an erector lens (d = 40) needs an astronomical (positive) eyepiece, not fe = -5",
      "enter the eyepiece's focal length and the erector distance again",
      "angular magnification D = 20 (erect)"],
     ["cm", "100", "5", "40"]),
    ("telescope Galileo too strong", "--telescope",
     ["cm", "100", "-100", "-5", "0"],
     ["|fe| = 100 is not less than fo = 100", "enter the eyepiece's focal length again",
      "angular magnification D = 20 (erect)"],
     ["cm", "100", "-5", "0"]),
    ("telescope on one line", "--telescope",
     ["cm 100 -5 40", "5 40"],
     ["needs an astronomical (positive) eyepiece", "D = 20 (erect)"],
     ["cm", "100", "5", "40"]),
    ("fit lsq equal object distances", "--fit",
     ["cm", "lsq", "10", "10", "-1", "10", "10", "-1", "n", "y", "20",
      "6.666666666666667", "-0.3333333333333333", "n"],
     ["all 2 object distances are 10", "add a measurement at another object distance",
      "Least-squares lens matrix from 3 measurements"],
     ["cm", "lsq", "10", "10", "-1", "10", "10", "-1", "y", "20", "6.666666666666667",
      "-0.33333333333333331", "n"]),
    ("fit cardinal focal on principal", "--fit",
     ["cm", "cardinal", "1", "1", "0", "5", "3", "11.470588235294118", "3",
      "-0.88235294117647056", "-16.764705882352942", "11.470588235294118",
      "-4.4117647058823533", "-0.88235294117647056"],
     ["the first focal point and principal point are both at z= 3",
      "enter the four points again", "Power P = -C = 0.0809524"],
     ["cm", "cardinal", "1", "1", "0", "5", "-16.764705882352942", "11.470588235294118",
      "-4.4117647058823533", "-0.88235294117647056"]),
    ("fit nodal focal on nodal", "--fit",
     ["cm", "nodal", "1", "1", "0", "5", "-3", "1", "3", "2",
      "-4.4117647058823533", "-0.88235294117647056", "16.764705882352942",
      "6.4705882352941178"],
     ["the first focal point and nodal point are both at z= -3",
      "enter the nodal points and focal lengths again", "Principal points: z= -4.41176"],
     ["cm", "nodal", "1", "1", "0", "5", "-4.4117647058823533", "-0.88235294117647056",
      "16.764705882352942", "6.4705882352941178"]),
    ("thick object at +inf", "--thick",
     ["cm", "1", "3", "5", "1.4", "4", "1", "y", "inf", "-inf", "n"],
     ["an object at infinity is at -inf (left of the lens), not +inf",
      "enter the object location again",
      "Object at infinity: the image is in the second focal plane z= 11.4706 (real)"],
     ["cm", "1", "3", "5", "1.4", "4", "1", "y", "-inf", "n"]),
    ("gauss object at +inf", "--gauss",
     ["cm", "1", "1.4", "3", "inf", "-inf", "n"],
     ["an object at infinity is at -inf (left of the surface)",
      "Image plane z2= 10.5 (real): the second focal point"],
     ["cm", "1", "1.4", "3", "-inf", "n"]),
    ("index by name", "--thick",
     ["cm", "air", "3", "5", "glass", "crown", "4", "Water", "n"],
     ["'glass' is not a number, nor a medium", "(crown: index 1.5168)",
      "(water: index 1.333)"],
     ["cm", "air", "3", "5", "crown", "4", "water", "n"]),
]

def main():
    bin_, home = sys.argv[1], sys.argv[2]
    bad = []
    for name, opt, typed, want, accepted in CASES:
        rec = os.path.join(home, "c.rec")
        # timeout: a dialogue that waits for more than was typed must not hang the test
        argv = ["/usr/bin/timeout", "--foreground", "-k", "5", "25", bin_, opt, rec]
        rc, out = drive(argv, [(t + "\n").encode() for t in typed], home=home, timeout=20,
                        quiet=0.15)
        miss = [w for w in want if w not in out]
        ins = [l[7:].rstrip("\n") for l in open(rec) if l.startswith("input: ")]
        if rc != 0:
            bad.append("%s: exit status %d, want 0" % (name, rc))
        for w in miss:
            bad.append("%s: screen lacks %r" % (name, w))
        if ins != accepted:
            bad.append("%s: record answers %r, want %r" % (name, ins, accepted))
        # the terminal's record is exactly what a replay of its answers writes
        rec2 = os.path.join(home, "c2.rec")
        with open(rec) as f:
            answers = "".join(l for l in f if l.startswith("input: "))
        r2 = subprocess.run([bin_, opt, rec2], input=answers.encode(),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if r2.returncode != 0 or open(rec).read() != open(rec2).read():
            bad.append("%s: the replay of the record's answers (exit %d) writes another "
                       "record" % (name, r2.returncode))
        if rc != 0 or miss or ins != accepted:
            bad.append("---- screen ----\n" + out[-2000:])
    for b in bad:
        print(b)
    return 1 if bad else 0

sys.exit(main())
