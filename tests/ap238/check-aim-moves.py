#!/usr/bin/env python3
"""Checks that the rs274 program stepnc compiles from an AP238 toolpath file
makes the file's moves: LinuxCNC's rs274 interpreter runs the program, and
its canonical moves must contain the expected moves, in order, within
0.001 mm: every vertex, arc end, centre and direction, the feed of every
feed move (within 0.01 mm/min) and the spindle speed and direction in force,
dwells by time.

The expected moves come from a file written by hand from the STEP-NC file
(not by stepnc), one per line, lengths in mm:

    spindle 3000 cw          the spindle state for the moves after it
    rapid X Y Z              a rapid ending at X Y Z
    line X Y Z F             a feed move to X Y Z at F mm/min
    arc X Y Z CX CY cw|ccw F an arc in XY to X Y Z about CX CY
    arc X Y Z C1 C2 cw|ccw F zx|yz
                             an arc in the ZX (G18) or YZ (G19) plane, its
                             centre C1 C2 in that plane's coordinates (ZX: z
                             then x; YZ: y then z), cw or ccw seen from +y
                             or +x, as LinuxCNC's canonical ARC_FEED has it
    dwell T                  a wait of T s

Between the file's moves the program may add rapids only (stepnc's own
links: up to the security plane, across, down), before an expected rapid or
after the last expected move; between two expected feed moves nothing may
be added. Exit 0 when the program makes the moves, 1 otherwise.
"""
import argparse
import importlib.util
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("check_rs274", os.path.join(HERE, "..", "backends", "check-rs274.py"))
sys.path.insert(0, os.path.join(HERE, "..", "backends"))
check_rs274 = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_rs274)

TOL = 1e-3
SPINDLE_RE = re.compile(r"(SET_SPINDLE_SPEED|START_SPINDLE_CLOCKWISE|START_SPINDLE_COUNTERCLOCKWISE|"
                        r"STOP_SPINDLE_TURNING)\(([^)]*)\)")


def spindle_states(canon_path):
    """The spindle state (speed, direction) at each motion line of the canon file, in order."""
    states, speed, direction = [], 0.0, "stop"
    motion = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|NURBS_FEED|DWELL)\(([^)]*)\)")
    with open(canon_path) as f:
        for line in f:
            m = SPINDLE_RE.search(line)
            if m:
                if m.group(1) == "SET_SPINDLE_SPEED":
                    speed = float(m.group(2).split(",")[-1])
                elif m.group(1) == "STOP_SPINDLE_TURNING":
                    direction = "stop"
                else:
                    direction = "cw" if m.group(1) == "START_SPINDLE_CLOCKWISE" else "ccw"
                continue
            m = motion.search(line)
            if m and not (m.group(1) == "DWELL" and float(m.group(2).split(",")[0]) == 0):
                states.append((speed, direction))
    return states


def read_expected(path):
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            words = line.split("#")[0].split()
            if not words:
                continue
            out.append((n, words[0], [w if w in ("cw", "ccw", "xy", "zx", "yz") else float(w) for w in words[1:]]))
    return out


def near(a, b):
    return all(abs(x - y) <= TOL for x, y in zip(a, b))


def compare(expected, moves, states):
    problems = []
    spindle = None
    i = 0
    for n, kind, args in expected:
        if kind == "spindle":
            spindle = (args[0], args[1])
            continue
        where = "expected line %d (%s %s)" % (n, kind, " ".join(str(a) for a in args))
        if kind == "rapid":
            while i < len(moves) and moves[i]["kind"] == "rapid" and not near(moves[i]["to"], args[:3]):
                i += 1
            if i >= len(moves) or moves[i]["kind"] != "rapid":
                return problems + ["%s: no rapid ends there before %s" %
                                   (where, moves[i]["text"] if i < len(moves) else "the end")]
            i += 1
            continue
        if i >= len(moves):
            return problems + ["%s: the program has no more moves" % where]
        m = moves[i]
        why = None
        if kind == "dwell":
            if m["kind"] != "dwell" or abs(m["time"] - args[0]) > 1e-6:
                why = "expected a dwell of %g s" % args[0]
        elif kind == "line":
            if m["kind"] != "linear" or not near(m["to"], args[:3]) or abs(m["feed"] - args[3]) > 0.01:
                why = "expected a feed move"
        elif kind == "arc":
            plane = args[7] if len(args) > 7 else "xy"
            if (m["kind"] != "arc" or m["plane"] != plane or not near(m["to"], args[:3]) or
                    not near(m["centre"], args[3:5]) or m["ccw"] != (args[5] == "ccw") or abs(m["feed"] - args[6]) > 0.01):
                why = "expected an arc in the %s plane" % plane.upper()
        else:
            why = "unknown expectation '%s'" % kind
        if not why and kind != "dwell" and spindle is not None:
            speed, direction = states[i]
            if abs(speed - spindle[0]) > 1e-6 or direction != spindle[1]:
                why = "the spindle turns %s at %g rev/min, expected %s at %g" % (direction, speed, spindle[1],
                                                                                 spindle[0])
        if why:
            problems.append("%s: %s, found %s" % (where, why, m["text"]))
            if len(problems) >= 5:
                return problems
        i += 1
    for m in moves[i:]:
        if m["kind"] != "rapid":
            problems.append("after the last expected move the program still moves at feed: %s" % m["text"])
            break
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stepnc", required=True)
    ap.add_argument("--program", help="check this program instead of compiling one (to show the check can fail)")
    ap.add_argument("input")
    ap.add_argument("expected")
    args, extra = ap.parse_known_args()
    with tempfile.TemporaryDirectory() as work:
        ngc = args.program or os.path.join(work, "prog.ngc")
        if not args.program:
            r = subprocess.run([args.stepnc, "compile", args.input, "--target=rs274", "--no-cycles", "-o", ngc] + extra,
                               capture_output=True, text=True)
            if r.returncode != 0:
                print("FAIL: stepnc could not compile %s:\n%s" % (args.input, r.stderr))
                return 1
        canon, error = check_rs274.run_rs274(ngc, work)
        if error:
            print("FAIL: " + error)
            return 1
        moves = check_rs274.canon_moves(canon, ngc)
        problems = compare(read_expected(args.expected), moves, spindle_states(canon))
    for p in problems:
        print("FAIL: %s: %s" % (os.path.basename(args.input), p))
    if not problems:
        print("ok: %s: the program makes the file's moves" % os.path.basename(args.input))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
