#!/usr/bin/env python3
"""Checks a 3+2 HEIDENHAIN TNC program that tilts the working plane to each
face (PLANE SPATIAL; docs/five-axis.md).

No TNC is at hand: the program is read here by its documented meaning
(PROCESSES.md C3), with check-heidenhain-tnc.py's reader (which also checks
its structure). `CYCL DEF 7.0 DATUM SHIFT` with 7.1 X, 7.2 Y, 7.3 Z moves the
datum to that point of the untilted coordinates; `PLANE SPATIAL SPA SPB SPC`
then tilts the coordinates about it by rotations about the fixed X, then Y,
then Z axes: a programmed point q is at shift + Rz(SPC) Ry(SPB) Rx(SPA) q in
the workpiece as clamped, and the tool lies along that turn's Z. Where the
program stops for a re-clamp (its message names the face put up), the
workpiece is placed as that face's setup places it from there on
(check-indexed.py).

Every feed move of the program (cycle 200 expanded as the TNC manual
describes it, arcs by their ends, centres and the points halfway along them)
taken back to the workpiece is compared with the toolpath IR's feed move in
its face's frame taken there (check-indexed.py reads them): within 0.001 mm,
and the tool's direction within 0.001 deg of the face's normal. Every turn
(PLANE ... TURN) must come right after the tool went up to the top of the
machine's z travel in machine coordinates (L Z.. R0 FMAX M91).

  check-working-plane.py --program P.h --ir I --machine M.toml

Exit status 0 when everything matches, 1 otherwise.
"""
import argparse
import importlib.util
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)


def load(name, file):
    spec = importlib.util.spec_from_file_location(name, os.path.join(HERE, file))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


check_indexed = load("check_indexed", "check-indexed.py")
klartext = load("check_heidenhain_tnc", "check-heidenhain-tnc.py")

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


def placed(frame, faces, q):
    """A point of the coordinates in force (frame: shift, angles, re-clamped
    face) as a point of the workpiece, and the tool's direction there."""
    shift, angles, face = frame
    turn = spatial(angles) if angles is not None else (lambda v: v)
    clamping = faces.get(face, check_indexed.IDENTITY) if face else check_indexed.IDENTITY
    point = check_indexed.add(shift, turn(q))
    return check_indexed.placed_back(clamping, point), check_indexed.turned_back(clamping, turn((0.0, 0.0, 1.0)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True)
    ap.add_argument("--ir", required=True)
    ap.add_argument("--machine", required=True, help="the machine's TOML file (its z travel)")
    args = ap.parse_args()
    chain = check_indexed.Chain(args.machine)
    with open(args.program, encoding="ascii", errors="replace") as f:
        checked, mach = klartext.check_program(f.read(), 0.001)
    problems = list(checked.items)
    setups, faces = check_indexed.read_setups(args.ir)
    if not mach.turns:
        problems.append("the program tilts no working plane")
    for turn in mach.turns:
        if turn["z"] is None or abs(turn["z"] - chain.z_top) > TOL_MM:
            problems.append("%s: the rotary axes turn with the tool at machine Z %s, not at the top of its travel %g" %
                            (turn["where"], turn["z"], chain.z_top))
    made = []
    for mv in klartext.program_moves(mach.motions):
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
    if len(made) != len(want):
        problems.append("%d feed moves in the program, %d in the IR" % (len(made), len(want)))
    worst_mm, worst_deg = 0.0, 0.0
    for w, g in zip(want, made):
        d = math.dist(w["to"], g["to"])
        if "centre" in w:
            d = max(d, math.dist(w["centre"], g.get("centre", (math.inf,) * 3)),
                    math.dist(w["middle"], g.get("middle", (math.inf,) * 3)))
        cosang = max(-1.0, min(1.0, sum(x * y for x, y in zip(w["normal"], g["axis"]))))
        deg = math.degrees(math.acos(cosang))
        worst_mm, worst_deg = max(worst_mm, d), max(worst_deg, deg)
        if d > TOL_MM or deg > TOL_DEG:
            problems.append("IR line %d (%s) against %s: %.4f mm, %.4f deg apart" %
                            (w["line"], w["text"], g["text"], d, deg))
            break
    if problems:
        for p in problems[:5]:
            print("FAIL: " + p)
        return 1
    print("ok: %d feed moves on %d faces, %d turns of the working plane, match through the datum shifts and "
          "spatial angles (largest %.4f mm, %.4f deg)" %
          (len(want), len({w["normal"] for w in want}), len(mach.turns), worst_mm, worst_deg))
    return 0


if __name__ == "__main__":
    sys.exit(main())
