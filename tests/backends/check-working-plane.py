#!/usr/bin/env python3
"""Checks a 3+2 program that tilts the working plane to each face
(docs/five-axis.md): a HEIDENHAIN TNC Klartext program (PLANE SPATIAL) or a
SINUMERIK 840D program (CYCLE800).

No TNC or 840D is at hand: the program is read here by its documented
meaning (PROCESSES.md C2, C3), with check-heidenhain-tnc.py's or
check-siemens-840d.py's reader (which also check its structure).

  - Klartext: `CYCL DEF 7.0 DATUM SHIFT` with 7.1 X, 7.2 Y, 7.3 Z moves the
    datum to that point of the untilted coordinates; `PLANE SPATIAL SPA SPB
    SPC` then tilts the coordinates about it by rotations about the fixed X,
    then Y, then Z axes: a programmed point q is at
    shift + Rz(SPC) Ry(SPB) Rx(SPA) q.
  - 840D: `CYCLE800(0,"TC",0,27,0,0,0,A,B,C,X1,Y1,Z1,-1,0)` turns the
    coordinates axis by axis, about Z by A, then about the turned Y by B,
    then about the twice turned X by C (_MODE 27), about the workpiece's
    origin (X0 Y0 Z0 0), and puts the zero at X1 Y1 Z1 of the turned
    coordinates: q is at Rz(A) Ry(B) Rx(C) (X1 + q). `_TC "0"` deselects.

That is a point of the workpiece as clamped, and the tool lies along that
turn's Z. Where the program stops for a re-clamp (its message names the face
put up), the workpiece is placed as that face's setup places it from there
on (check-indexed.py).

Every feed move of the program (cycle 200 expanded as the TNC manual
describes it, arcs by their ends, centres and the points halfway along them)
taken back to the workpiece is compared with the toolpath IR's feed move in
its face's frame taken there (check-indexed.py reads them): within 0.001 mm,
and the tool's direction within 0.001 deg of the face's normal. Every turn
(PLANE ... TURN, CYCLE800) must come right after the tool went up to the top
of the machine's z travel in machine coordinates (L Z.. R0 FMAX M91, G0 SUPA
Z..). The dialect is taken from the file's extension (.h: Klartext, else
840D).

  check-working-plane.py --program P.h|P.mpf --ir I --machine M.toml

Exit status 0 when everything matches, 1 otherwise.
"""
import argparse
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from toolpath_ir import load_script as load  # noqa: E402

check_indexed = load("check_indexed", "check-indexed.py")
klartext = load("check_heidenhain_tnc", "check-heidenhain-tnc.py")
siemens = load("check_siemens_840d", "check-siemens-840d.py")

TOL_MM = 1e-3
TOL_DEG = 1e-3


def spatial(angles):
    """The turn of PLANE SPATIAL SPA SPB SPC (deg) as a function of a
    vector: about the fixed X by SPA, then Y by SPB, then Z by SPC."""
    a, b, c = angles

    def turn(v):
        v = check_indexed.rotate(v, (1.0, 0.0, 0.0), a)
        v = check_indexed.rotate(v, (0.0, 1.0, 0.0), b)
        return check_indexed.rotate(v, (0.0, 0.0, 1.0), c)
    return turn


def axis_by_axis(angles):
    """CYCLE800's turn axis by axis, Z then Y then X (deg), each about the
    axis as the turns before left it: Rz(A) Ry(B) Rx(C) of a vector, which
    is PLANE SPATIAL's with the angles the other way round."""
    a, b, c = angles
    return spatial((c, b, a))


def placed(frame, faces, q):
    """A point of the coordinates in force as a point of the workpiece, and
    the tool's direction there. frame: ("cycle800", (angles, rotated zero)
    or None, re-clamped face) from the 840D's reader, or (datum shift,
    spatial angles or None, re-clamped face) from the TNC's."""
    if frame[0] == "cycle800":
        _, swivel, face = frame
        turn = axis_by_axis(swivel[0]) if swivel else (lambda v: v)
        point = turn(check_indexed.add(swivel[1], q) if swivel else q)
    else:
        shift, angles, face = frame
        turn = spatial(angles) if angles is not None else (lambda v: v)
        point = check_indexed.add(shift, turn(q))
    clamping = faces.get(face, check_indexed.IDENTITY) if face else check_indexed.IDENTITY
    return check_indexed.placed_back(clamping, point), check_indexed.turned_back(clamping, turn((0.0, 0.0, 1.0)))


def klartext_motions(text):
    """The problems of a Klartext program, its turns and its motions (with
    their start points)."""
    checked, mach = klartext.check_program(text, 0.001)
    return list(checked.items), mach.turns, klartext.program_moves(mach.motions)


def siemens_motions(name, text):
    """The problems of an 840D program, its swivels and its motions (with
    their start points, in three coordinates)."""
    c = siemens.check_text(name, text, 0)
    motions, at = [], None
    for mv in c.made:
        mv = dict(mv)
        if mv["kind"] == "arc" and mv.get("plane", "xy") != "xy":
            c.problems.append("line %d: an arc outside the XY plane, which this check does not read" % mv["line"])
        mv["start"] = at if at is not None and None not in at else None
        mv["where"] = "line %d" % mv["line"]
        motions.append(mv)
        at = mv["to"]
    return list(c.problems), c.turns, motions


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True)
    ap.add_argument("--ir", required=True)
    ap.add_argument("--machine", required=True, help="the machine's TOML file (its z travel)")
    args = ap.parse_args()
    chain = check_indexed.Chain(args.machine)
    with open(args.program, encoding="ascii", errors="replace") as f:
        text = f.read()
    if args.program.lower().endswith(".h"):
        problems, turns, motions = klartext_motions(text)
    else:
        problems, turns, motions = siemens_motions(os.path.basename(args.program), text)
    setups, faces = check_indexed.read_setups(args.ir)
    if not turns:
        problems.append("the program tilts no working plane")
    for turn in turns:
        if turn["z"] is None or abs(turn["z"] - chain.z_top) > TOL_MM:
            problems.append("%s: the rotary axes turn with the tool at machine Z %s, not at the top of its travel %g" %
                            (turn["where"], turn["z"], chain.z_top))
    made = []
    for mv in motions:
        if mv["kind"] not in ("linear", "arc") or mv.get("tcp"):
            continue
        if mv["kind"] == "arc" and mv["start"] is None:
            problems.append("%s: an arc from an unknown position" % mv["where"])
            continue
        to, axis = placed(mv["frame"], faces, mv["to"])
        entry = {"to": to, "axis": axis, "text": mv["where"]}
        if mv["kind"] == "arc":
            centre = (mv["centre"][0], mv["centre"][1], mv["start"][2])
            middle = check_indexed.arc_middle(mv["start"], mv["to"], mv["centre"], mv["ccw"], mv["sweep"], "xy")
            entry["centre"] = placed(mv["frame"], faces, centre)[0]
            entry["middle"] = placed(mv["frame"], faces, middle)[0]
        made.append(entry)
    want = check_indexed.ir_feed_moves(args.ir, setups)
    worst_mm, worst_deg = check_indexed.compare_feed_moves(want, made, problems)
    if problems:
        for p in problems[:5]:
            print("FAIL: " + p)
        return 1
    print("ok: %d feed moves on %d faces, %d turns of the working plane, match through the working planes "
          "in force (largest %.4f mm, %.4f deg)" %
          (len(want), len({w["normal"] for w in want}), len(turns), worst_mm, worst_deg))
    return 0


if __name__ == "__main__":
    sys.exit(main())
