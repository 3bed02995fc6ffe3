#!/usr/bin/env python3
"""Checks the steps that tilt the tool of a program written with the
controller's tool-centre-point control (docs/five-axis.md): a SINUMERIK
840D program (TRAORI) or a HEIDENHAIN TNC Klartext program (FUNCTION TCPM).

No 840D or TNC interpreter is at hand: the program is read here by its
documented meaning (PROCESSES.md C2, C3). Between TRAORI and TRAFOOF, or
between `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS` and `FUNCTION RESET
TCPM`, X Y Z are the tool tip in the workpiece and the rotary words (A, B,
C) the machine's rotary axes (AXIS POS), which the controller moves in
proportion along each block (PATHCTRL AXIS) while it keeps the tip on the
block's line, at the feed along the tip's path (F TCP). A FUNCTION TCPM
with other options is refused: the check relies on these. The tool's direction for the angles is
taken through the machine's forward kinematics, written in check-indexed.py
from the machine file alone. The toolpath IR gives each move at feed of a
step that tilts the tool (check-five-axis.py reads them). For each:

  - the block that ends the move ends at its tip and axis (within the
    program's rounding: 0.001 mm, 0.002 deg), and every block before it ends
    on the move;
  - halfway through each block (the angles halfway) the tool's direction is
    within --axis-tolerance deg of the IR's there;
  - each block's F is the IR's feed (mm/min along the tip's path; within
    the program's rounding: 0.05 on the 840D, 0.5 on the TNC).

Every transformation that is turned on is turned off, with the rotary axes
back at 0 before it goes. The dialect is taken from the file's extension
(.h: Klartext) unless --dialect says.

  check-tcp.py --program P.MPF --ir I --machine M.toml [--dialect siemens|klartext]

Exit status 0 when everything matches, 1 otherwise.
"""
import argparse
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from toolpath_ir import load_script as load  # noqa: E402

check_indexed = load("check_indexed", "check-indexed.py")
five = load("check_five_axis", "check-five-axis.py")

TOL_MM = 1e-3
TOL_DEG = 2e-3
WORD_RE = re.compile(r"([A-Z]+)(=?)(-?[0-9.]+)")


FEED_TOL = {"siemens": 0.05, "klartext": 0.5}
TCPM_ON = "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS"
TCPM_OFF = "FUNCTION RESET TCPM"
KLARTEXT_WORD_RE = re.compile(r"^([XYZABC])([+-][0-9]+(?:\.[0-9]+)?)$")


def switched(n, word, turning_on, on, at, problems):
    """Tool-centre-point control switched on or off by `word` at line n: a
    problem when it already is, or when it goes off with the rotary axes not
    back at 0. Returns whether it is on after."""
    if on == turning_on:
        problems.append("line %d: %s while it is %s" % (n, word, "on" if on else "off"))
    if not turning_on and any(abs(at[a]) > 1e-9 for a in "ABC"):
        problems.append("line %d: %s with the rotary axes at A%g B%g C%g, not 0" % (n, word, at["A"], at["B"], at["C"]))
    return turning_on


def klartext_blocks(path):
    """The feed blocks (L without FMAX) under FUNCTION TCPM: their start and
    end tip and angles and F; and the problems of its use."""
    blocks, problems = [], []
    on = False
    at = {"X": 0.0, "Y": 0.0, "Z": 0.0, "A": 0.0, "B": 0.0, "C": 0.0}
    feed = 0.0
    with open(path) as f:
        for n, line in enumerate(f, 1):
            parts = line.split(";")[0].strip().split(" ", 1)
            if len(parts) < 2 or not parts[0].isdigit():
                continue  # a cycle's parameter line, or an empty one
            body = parts[1].strip()
            if body.startswith("FUNCTION TCPM"):
                if body != TCPM_ON:
                    problems.append("line %d: %s is not %s, whose meaning this check reads" % (n, body, TCPM_ON))
                on = switched(n, "FUNCTION TCPM", True, on, at, problems)
                continue
            if body == TCPM_OFF:
                on = switched(n, "FUNCTION RESET TCPM", False, on, at, problems)
                continue
            words = body.split()
            if not words or words[0] != "L":
                if any(re.match(r"^[ABC][+-]", w) for w in words):
                    problems.append("line %d: rotary words outside an L block" % n)
                continue
            before = dict(at)
            rapid = "FMAX" in words
            for w in words[1:]:
                m = KLARTEXT_WORD_RE.match(w)
                if m:
                    at[m.group(1)] = float(m.group(2))
                    if m.group(1) in "ABC" and not on:
                        problems.append("line %d: rotary words with FUNCTION TCPM off" % n)
                elif re.match(r"^F[0-9.]+$", w):
                    feed = float(w[1:])
            if on and not rapid and at != before:
                blocks.append({"from": before, "to": dict(at), "feed": feed, "text": "line %d: %s" % (n, body)})
    if on:
        problems.append("the program ends with FUNCTION TCPM on")
    return blocks, problems


def siemens_blocks(path):
    """The G1 blocks under TRAORI: their start and end tip and angles and F;
    and the problems of the transformation's use."""
    blocks, problems = [], []
    on = False
    at = {"X": 0.0, "Y": 0.0, "Z": 0.0, "A": 0.0, "B": 0.0, "C": 0.0}
    motion, feed = None, 0.0
    with open(path) as f:
        for n, line in enumerate(f, 1):
            code = line.split(";")[0].strip()
            if code == "TRAORI":
                on = switched(n, "TRAORI", True, on, at, problems)
                continue
            if code == "TRAFOOF":
                on = switched(n, "TRAFOOF", False, on, at, problems)
                continue
            words = dict((w, float(v)) for w, _, v in WORD_RE.findall(code) if w in ("G", "X", "Y", "Z", "A", "B", "C", "F"))
            if "G" in words and words["G"] in (0, 1):
                motion = int(words["G"])
            if "F" in words:
                feed = words["F"]
            before = dict(at)
            for k in ("X", "Y", "Z", "A", "B", "C"):
                if k in words:
                    at[k] = words[k]
            if any(k in words for k in "ABC") and not on:
                problems.append("line %d: rotary words with the transformation off" % n)
            if on and motion == 1 and at != before:
                blocks.append({"from": before, "to": dict(at), "feed": feed, "text": "line %d: %s" % (n, code)})
    if on:
        problems.append("the program ends with the transformation on")
    return blocks, problems


def pose(chain, words):
    tip = (words["X"], words["Y"], words["Z"])
    axis = chain.to_workpiece((0.0, 0.0, 0.0), {"a": words["A"], "b": words["B"], "c": words["C"]}, (0.0, 0.0, 0.0))[1]
    return tip, axis


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True)
    ap.add_argument("--ir", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--axis-tolerance", type=float, default=0.01)
    ap.add_argument("--dialect", choices=("siemens", "klartext"))
    args = ap.parse_args()
    dialect = args.dialect or ("klartext" if args.program.lower().endswith(".h") else "siemens")
    chain = check_indexed.Chain(args.machine)
    blocks, problems = (klartext_blocks if dialect == "klartext" else siemens_blocks)(args.program)
    want, _ = five.tilted_moves(args.ir)
    if not want:
        problems.append("the IR has no step that tilts the tool")
    worst_end, worst_mid = (0.0, 0.0), 0.0
    k = 0
    for mv in want:
        while not problems:
            if k == len(blocks):
                problems.append("IR line %d (%s): no block ends at its end" % (mv["line"], mv["text"]))
                break
            b = blocks[k]
            k += 1
            tip, axis = pose(chain, b["to"])
            mm, deg, _ = five.on_move(mv, tip, axis)
            half = {a: (b["from"][a] + b["to"][a]) / 2 for a in b["to"]}
            mid_tip, mid_axis = pose(chain, half)
            _, mid_deg, _ = five.on_move(mv, mid_tip, mid_axis)
            worst_mid = max(worst_mid, mid_deg)
            if mid_deg > args.axis_tolerance + TOL_DEG:
                problems.append("%s: halfway through, the tool is %.4f deg off IR line %d" % (b["text"], mid_deg, mv["line"]))
            if abs(b["feed"] - mv["feed"]) > FEED_TOL[dialect] + 1e-9:
                problems.append("%s: F%g where the IR's feed is %g mm/min" % (b["text"], b["feed"], mv["feed"]))
            end = math.dist(tip, mv["to"]), five.angle(axis, mv["axis"])
            if end[0] <= TOL_MM and end[1] <= TOL_DEG:
                worst_end = (max(worst_end[0], end[0]), max(worst_end[1], end[1]))
                break
            # Where along the move a block ends is read from its tip, printed
            # to 0.001 mm: the axis there is known within the turn over that.
            length = math.dist(mv["start"], mv["to"])
            slack = five.angle(mv["from_axis"], mv["axis"]) * (TOL_MM / length if length > 0 else 1.0)
            if mm > TOL_MM or deg > TOL_DEG + slack:
                problems.append("%s ends %.4f mm and %.4f deg off IR line %d (%s)" %
                                (b["text"], mm, deg, mv["line"], mv["text"]))
                break
        if problems:
            break
    if not problems and k != len(blocks):
        problems.append("%d blocks at feed under tool-centre-point control after the IR's last move: %s" %
                        (len(blocks) - k, blocks[k]["text"]))
    if problems:
        for p in problems[:5]:
            print("FAIL: " + p)
        return 1
    print("ok: %d moves at feed that tilt the tool, in %d blocks under %s, match through the machine's "
          "kinematics: ends within %.4f mm and %.4f deg, halfway within %.4f deg" %
          (len(want), len(blocks), "FUNCTION TCPM" if dialect == "klartext" else "TRAORI", worst_end[0],
           worst_end[1], worst_mid))
    return 0


if __name__ == "__main__":
    sys.exit(main())
