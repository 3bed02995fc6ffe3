#!/usr/bin/env python3
"""Checks the steps that tilt the tool (continuous 5-axis) of an rs274
program written as a machine's joints (docs/five-axis.md).

The program is run through LinuxCNC's rs274 interpreter with the work offset
G54 set where the workpiece's origin is (--work-offset). Every canonical
block, in machine coordinates (its position plus the G54 offset rs274
reports) with its rotary angles, is taken back to the workpiece through the
machine's forward kinematics, written in check-indexed.py from the machine
file alone: the tool tip and the tool's direction. The toolpath IR says
where each move at feed of a step that tilts the tool goes: from its start
pose to its end pose, the tip along the line and the axis turning evenly in
the plane of its two ends (the IR's rule).

For each such IR move, in order, the program's blocks inside the inverse-time
(G93) sections:
  - the block that ends the move ends at its pose, within 0.001 mm and
    0.001 deg, and every block before it ends on the move (its tip within
    0.001 mm of the line, its axis within 0.001 deg of the IR's there);
  - halfway through each block (the joints halfway, which is where the
    controller has them) the tip and axis are within --tolerance mm and
    --axis-tolerance deg of the IR's move;
  - the blocks take the time the IR's feed gives the move (their length in
    X Y Z over the rate rs274 derives from the inverse-time F), within 0.5 %;
  - no block turns a rotary axis by 90 deg or more (a flip).
Every change of the rotary axes at rapid happens with the tool at the top of
the machine's z travel. The moves at feed of the other steps (the tool
upright, the rotary axes at 0) are compared one by one with the IR's, as
check-indexed.py does: ends, and arcs' centres and middles, within 0.001 mm.

  check-five-axis.py --program P --ir I --machine M.toml --work-offset X,Y,Z

Exit status 0 when everything matches, 1 otherwise.
"""
import argparse
import importlib.util
import math
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import toolpath_ir  # noqa: E402

spec = importlib.util.spec_from_file_location("check_indexed", os.path.join(HERE, "check-indexed.py"))
check_indexed = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_indexed)
check_rs274 = check_indexed.check_rs274

TOL_MM = 1e-3
TOL_DEG = 1e-3
FLIP_DEG = 90.0
CANON_RE = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SET_G5X_OFFSET|SET_FEED_RATE|SELECT_PLANE)\(([^)]*)\)")
MOVES_RE = re.compile(r"^\s*moves ")


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def unit(v):
    n = norm(v)
    return tuple(x / n for x in v)


def angle(u, w):
    """deg between two directions."""
    cross = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    return math.degrees(math.atan2(norm(cross), sum(a * b for a, b in zip(u, w))))


def slerp(u, w, t):
    """The axis a fraction t from u to w, turning evenly in their plane."""
    a = math.radians(angle(u, w))
    if a < 1e-12:
        return w if t >= 1 else u
    s = math.sin(a)
    return unit(tuple(math.sin((1 - t) * a) / s * x + math.sin(t * a) / s * y for x, y in zip(u, w)))


def tilted_moves(ir_path):
    """The moves at feed of the IR's steps that tilt the tool, in order:
    start and end tip, start and end axis, length, feed; and those of the
    other steps (the tool upright), with an arc's centre and middle."""
    blocks = []
    with open(ir_path) as f:
        for n, line in enumerate(f, 1):
            if MOVES_RE.match(line):
                blocks.append(n)
    by_block = {}
    for mv in toolpath_ir.read_moves(ir_path):
        block = max((b for b in blocks if b < mv["line"]), default=0)
        by_block.setdefault(block, []).append(mv)
    out, upright = [], []
    for block in sorted(by_block):
        moves = by_block[block]
        if not any(m.get("axis", (0.0, 0.0, 1.0)) != (0.0, 0.0, 1.0) for m in moves):
            for m in moves:
                if m["kind"] not in ("linear", "arc"):
                    continue
                entry = {"to": m["to"], "line": m["line"], "text": m["text"]}
                if m["kind"] == "arc":
                    centre = toolpath_ir.world(tuple(m["centre"]) + (toolpath_ir.local(m["start"], m["plane"])[2],),
                                               m["plane"])
                    entry["centre"] = centre
                    entry["middle"] = check_indexed.arc_middle(m["start"], m["to"], m["centre"], m["ccw"],
                                                               m["sweep"], m["plane"])
                upright.append(entry)
            continue
        axis = (0.0, 0.0, 1.0)
        for m in moves:
            to_axis = unit(m.get("axis", (0.0, 0.0, 1.0)))
            if m["kind"] == "arc":
                raise SystemExit("check-five-axis: an arc in a step that tilts the tool (IR line %d)" % m["line"])
            if m["kind"] == "linear":
                out.append({"start": m["start"], "to": m["to"], "from_axis": axis, "axis": to_axis,
                            "feed": m["feed"], "line": m["line"], "text": m["text"]})
            if m["kind"] != "dwell":
                axis = to_axis
    return out, upright


def canon_blocks(canon_path, chain, work_offset):
    """The canonical blocks at feed in inverse time, each with its start and
    end joints (machine x, y, z and the angles) and its rate; the other
    moves at feed, taken to the workpiece (an arc's centre and middle too);
    and the problems of turns made at rapid below the top of z."""
    blocks, upright, problems = [], [], []
    plane = "xy"
    at = (0.0, 0.0, 0.0)  # where the tool is, program coordinates
    offset = (0.0, 0.0, 0.0)
    joints = None  # (x, y, z) machine, {a, b, c}
    inverse = False
    rate = 0.0
    with open(canon_path) as f:
        for n, line in enumerate(f, 1):
            if "feed mode set to inverse time" in line:
                inverse = True
                continue
            if "feed mode set to units per minute" in line:
                inverse = False
                continue
            m = CANON_RE.search(line)
            if not m:
                continue
            if m.group(1) == "SELECT_PLANE":
                plane = check_rs274.CANON_PLANES[m.group(2).strip()]
                continue
            args = [float(a) for a in m.group(2).split(",")]
            if m.group(1) == "SET_G5X_OFFSET":
                offset = tuple(args[1:4])
                continue
            if m.group(1) == "SET_FEED_RATE":
                rate = args[0]
                continue
            if m.group(1) == "ARC_FEED":
                # Upright steps' arcs: their end, centre and middle.
                e1, e2, c1, c2, turn, e3, a, b, c = args[:9]
                to = toolpath_ir.world((e1, e2, e3), plane)
                centre = toolpath_ir.world((c1, c2, e3), plane)
                sweep = toolpath_ir.arc_sweep(toolpath_ir.local(at, plane), (e1, e2), (c1, c2), turn > 0) + \
                    2 * math.pi * (abs(int(turn)) - 1)
                middle = check_indexed.arc_middle(at, to, (c1, c2), turn > 0, sweep, plane)
                angles = {"a": a, "b": b, "c": c}

                def back(q):
                    return chain.to_workpiece(check_indexed.add(q, offset), angles, work_offset)[0]
                upright.append({"to": back(to), "centre": back(centre), "middle": back(middle),
                                "text": "canon line %d: %s" % (n, line.strip())})
                at = to
                joints = (check_indexed.add(to, offset), angles)
                continue
            at = tuple(args[:3])
            to = check_indexed.add(tuple(args[:3]), offset)
            angles = {"a": args[3], "b": args[4], "c": args[5]}
            if m.group(1) == "STRAIGHT_TRAVERSE":
                if joints and angles != joints[1]:
                    for z in (joints[0][2], to[2]):
                        if not abs(z - chain.z_top) <= TOL_MM:
                            problems.append("canon line %d: the rotary axes turn at rapid with the tool at machine "
                                            "z %.4f, not at the top of its travel %g" % (n, z, chain.z_top))
                joints = (to, angles)
                continue
            if inverse and joints:
                blocks.append({"from": joints, "to": (to, angles), "rate": rate,
                               "text": "canon line %d: %s" % (n, line.strip())})
            elif not inverse:
                upright.append({"to": chain.to_workpiece(to, angles, work_offset)[0],
                                "text": "canon line %d: %s" % (n, line.strip())})
            joints = (to, angles)
    return blocks, upright, problems


def pose(chain, joints, work_offset):
    return chain.to_workpiece(joints[0], joints[1], work_offset)


def halfway(a, b):
    return (tuple((x + y) / 2 for x, y in zip(a[0], b[0])), {k: (a[1][k] + b[1][k]) / 2 for k in a[1]})


def on_move(move, tip, axis):
    """How far a pose is from the IR's move: (mm, deg, t)."""
    p0, p1 = move["start"], move["to"]
    d = check_indexed.sub(p1, p0)
    length2 = sum(x * x for x in d)
    if length2 > 1e-18:
        t = max(0.0, min(1.0, sum(x * y for x, y in zip(check_indexed.sub(tip, p0), d)) / length2))
    else:
        # Turning in place: where the axis is along its turn.
        total = angle(move["from_axis"], move["axis"])
        t = max(0.0, min(1.0, angle(move["from_axis"], axis) / total)) if total > 0 else 1.0
    on = tuple(a + t * b for a, b in zip(p0, d))
    return math.dist(on, tip), angle(slerp(move["from_axis"], move["axis"], t), axis), t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True)
    ap.add_argument("--ir", required=True)
    ap.add_argument("--machine", required=True, help="the machine's TOML file (table-table, head-table, head-head)")
    ap.add_argument("--work-offset", required=True)
    ap.add_argument("--tolerance", type=float, default=0.002, help="mm the tip may leave the move halfway through a block")
    ap.add_argument("--axis-tolerance", type=float, default=0.01, help="deg the axis may leave the move there")
    args = ap.parse_args()
    work_offset = tuple(float(v) for v in args.work_offset.split(","))
    chain = check_indexed.Chain(args.machine)
    with tempfile.TemporaryDirectory() as work:
        canon, why = check_indexed.run_with_offset(args.program, work, work_offset)
        if not canon:
            print("FAIL: " + why)
            return 1
        blocks, made_upright, problems = canon_blocks(canon, chain, work_offset)
    want, want_upright = tilted_moves(args.ir)
    if not want:
        problems.append("the IR has no step that tilts the tool")
    # The steps with the tool upright: move by move, as check-indexed.py does.
    if len(made_upright) != len(want_upright):
        problems.append("%d moves at feed with the tool upright in the program, %d in the IR" %
                        (len(made_upright), len(want_upright)))
    upright_mm = 0.0
    for w, g in zip(want_upright, made_upright):
        d = math.dist(w["to"], g["to"])
        if "centre" in w:
            d = max(d, math.dist(w["centre"], g.get("centre", (math.inf,) * 3)),
                    math.dist(w["middle"], g.get("middle", (math.inf,) * 3)))
        upright_mm = max(upright_mm, d)
        if d > TOL_MM:
            problems.append("IR line %d (%s) against %s: %.4f mm apart" % (w["line"], w["text"], g["text"], d))
            break
    worst = {"end": (0.0, 0.0), "on": (0.0, 0.0), "mid": (0.0, 0.0), "time": 0.0}
    k = 0
    for mv in want:
        length = math.dist(mv["start"], mv["to"])
        minutes = 0.0
        timed = length > 0
        while True:
            if k == len(blocks):
                problems.append("IR line %d (%s): no block of the program ends at its end" % (mv["line"], mv["text"]))
                break
            b = blocks[k]
            k += 1
            tip, axis = pose(chain, b["to"], work_offset)
            mm, deg, t = on_move(mv, tip, axis)
            mid_tip, mid_axis = pose(chain, halfway(b["from"], b["to"]), work_offset)
            mid_mm, mid_deg, _ = on_move(mv, mid_tip, mid_axis)
            swing = max(abs(b["to"][1][a] - b["from"][1][a]) for a in "abc")
            worst["mid"] = (max(worst["mid"][0], mid_mm), max(worst["mid"][1], mid_deg))
            if swing >= FLIP_DEG:
                problems.append("%s: a rotary axis turns %.3f deg in one block (a flip)" % (b["text"], swing))
            if mid_mm > args.tolerance + TOL_MM or mid_deg > args.axis_tolerance + TOL_DEG:
                problems.append("%s: halfway through, the tool is %.4f mm and %.4f deg off IR line %d (%s)" %
                                (b["text"], mid_mm, mid_deg, mv["line"], mv["text"]))
            xyz = math.dist(b["from"][0], b["to"][0])
            if xyz > 1e-9 and b["rate"] > 0:
                minutes += xyz / b["rate"]
            else:
                timed = False
            end = math.dist(tip, mv["to"]), angle(axis, mv["axis"])
            if end[0] <= TOL_MM and end[1] <= TOL_DEG:
                worst["end"] = (max(worst["end"][0], end[0]), max(worst["end"][1], end[1]))
                break
            worst["on"] = (max(worst["on"][0], mm), max(worst["on"][1], deg))
            if mm > TOL_MM or deg > TOL_DEG:
                problems.append("%s ends %.4f mm and %.4f deg off IR line %d (%s)" %
                                (b["text"], mm, deg, mv["line"], mv["text"]))
                break
        if problems:
            break
        if timed:
            planned = length / mv["feed"]
            off = abs(minutes - planned) / planned
            worst["time"] = max(worst["time"], off)
            if off > 0.005:
                problems.append("IR line %d (%s): the blocks take %.6f min, the feed %.6f min" %
                                (mv["line"], mv["text"], minutes, planned))
                break
    if not problems and k != len(blocks):
        problems.append("%d blocks in inverse time after the IR's last move: %s" % (len(blocks) - k, blocks[k]["text"]))
    if problems:
        for p in problems[:5]:
            print("FAIL: " + p)
        return 1
    print("ok: %d moves at feed that tilt the tool, in %d blocks, match through the machine's kinematics: ends "
          "within %.4f mm and %.4f deg, blocks on the moves within %.4f mm and %.4f deg, halfway within %.4f mm and "
          "%.4f deg, times within %.3f %%; %d moves with the tool upright within %.4f mm" %
          (len(want), len(blocks), worst["end"][0], worst["end"][1], worst["on"][0], worst["on"][1],
           worst["mid"][0], worst["mid"][1], 100 * worst["time"], len(want_upright), upright_mm))
    return 0


if __name__ == "__main__":
    sys.exit(main())
