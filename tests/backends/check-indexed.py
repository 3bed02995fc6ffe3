#!/usr/bin/env python3
"""Checks a 3+2 (indexed) rs274 program on a 5-axis machine (table-table,
head-table, head-head).

A part with features on several faces, compiled for a machine whose rotary
table turns each face to the tool (docs/five-axis.md), is run through
LinuxCNC's rs274 interpreter with the work offset G54 set where the
workpiece's origin is (--work-offset). Each canonical move, in machine
coordinates (its position plus the G54 offset rs274 reports), is taken back
to the workpiece through the machine's forward kinematics, written here from
the machine file alone (the head's axes turning the tip's offset from its
pivot and the tool, then each table axis's turn undone, the outermost
first): the tool tip in workpiece coordinates and the tool's direction
there. The toolpath IR says where each feed move should be, in
its face's setup frame: taken to the workpiece through the setup's
workpiece_setup placement. The two are compared move by move (feed moves;
arcs by their ends, centres and the points halfway along them, which tells
the way round) within 0.001 mm, and the tool's direction
within 0.001 deg of the face's normal. Every turn of the rotary axes must
happen with the tool at the top of the machine's z travel. Where the
program stops for a re-clamp (its message names the face put up), the
workpiece is taken as that face's setup places it from there on.

  check-indexed.py --program P --ir I --machine M.toml --work-offset X,Y,Z

Exit status 0 when everything matches, 1 otherwise.
"""
import argparse
import importlib.util
import math
import os
import re
import sys
import tempfile
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import toolpath_ir  # noqa: E402

spec = importlib.util.spec_from_file_location("check_rs274", os.path.join(HERE, "check-rs274.py"))
check_rs274 = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_rs274)

TOL_MM = 1e-3
TOL_DEG = 1e-3
AXIS_DIRECTIONS = {"a": (1.0, 0.0, 0.0), "b": (0.0, 1.0, 0.0), "c": (0.0, 0.0, 1.0)}
CANON_RE = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SET_G5X_OFFSET|SELECT_PLANE)\(([^)]*)\)")
MESSAGE_RE = re.compile(r'MESSAGE\("(.*)"\)')
RECLAMP_RE = re.compile(r"re-clamp the workpiece with its ([+-][XYZ]) face up")
SETUP_RE = re.compile(r"^\s*setup (%\S+)(?:.*face_up=([+-][xyz]))?")
WPS_RE = re.compile(r"^\s*workpiece_setup .*at=\(([^)]*)\)mm axis=\(([^)]*)\) ref=\(([^)]*)\)")
MOVES_RE = re.compile(r"^\s*moves .*setup=(%\S+)")


def rotate(v, axis, deg):
    """v turned by deg about the unit axis (right-handed)."""
    t = math.radians(deg)
    c, s = math.cos(t), math.sin(t)
    ax, ay, az = axis
    dot = ax * v[0] + ay * v[1] + az * v[2]
    cross = (ay * v[2] - az * v[1], az * v[0] - ax * v[2], ax * v[1] - ay * v[0])
    return tuple(v[k] * c + cross[k] * s + (ax, ay, az)[k] * dot * (1 - c) for k in range(3))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


class Chain:
    """The rotary axes of a table-table, head-table or head-head machine file: the
    head's (turning the tool about a pivot measured from its tip) and the
    table's (turning the workpiece about pivots in machine coordinates),
    each list from the machine's base outwards."""

    def __init__(self, path):
        with open(path, "rb") as f:
            data = tomllib.load(f)
        kin = data["kinematics"]
        if kin.get("type") not in ("table-table", "head-table", "head-head"):
            raise SystemExit("check-indexed: %s is not a table-table, head-table or head-head machine" % path)

        def axes(names):
            return [(n, AXIS_DIRECTIONS[n], tuple(data["axes"][n].get("pivot", (0.0, 0.0, 0.0)))) for n in names]
        self.head = axes(kin.get("head", []))
        self.table = axes(kin.get("table", []))
        self.tool = tuple(kin.get("tool_axis", (0.0, 0.0, 1.0)))
        self.z_top = data["axes"]["z"]["travel"][1]

    def to_workpiece(self, joints_xyz, angles, work_offset):
        """The tool tip and direction in workpiece coordinates for the
        linear axes' positions (machine coordinates) and the rotary angles:
        the head turns the tip's offset and the tool (innermost first), then
        the table's turns are undone (outermost first)."""
        offset, k = (0.0, 0.0, 0.0), self.tool
        for name, direction, pivot in reversed(self.head):
            offset = add(pivot, rotate(sub(offset, pivot), direction, angles[name]))
            k = rotate(k, direction, angles[name])
        tip = add(joints_xyz, offset)
        for name, direction, pivot in self.table:
            tip = add(pivot, rotate(sub(tip, pivot), direction, -angles[name]))
            k = rotate(k, direction, -angles[name])
        return sub(tip, work_offset), k


def arc_middle(start, end, centre, ccw, sweep, plane):
    """The point halfway along an arc (plane coordinates in, world out): its
    start turned half its sweep about the centre, the normal coordinate
    halfway (a helix)."""
    s, e = toolpath_ir.local(start, plane), toolpath_ir.local(end, plane)
    cx, cy = centre
    half = (sweep / 2) * (1 if ccw else -1)
    dx, dy = s[0] - cx, s[1] - cy
    x = cx + dx * math.cos(half) - dy * math.sin(half)
    y = cy + dx * math.sin(half) + dy * math.cos(half)
    return toolpath_ir.world((x, y, (s[2] + e[2]) / 2), plane)


IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))


def read_setups(ir_path):
    """Each setup's placement of the workpiece, (at, z axis, x axis), and
    the placement of each face's setup by the face ("+X"; "+Z": as first
    clamped)."""
    setups, faces, current = {}, {"+Z": IDENTITY}, None
    with open(ir_path) as f:
        for line in f:
            m = SETUP_RE.match(line)
            if m:
                current = (m.group(1), m.group(2))
                continue
            m = WPS_RE.match(line)
            if m and current:
                vec = [tuple(float(v) for v in g.split(",")) for g in m.groups()]
                setups[current[0]] = vec
                if current[1]:
                    faces[current[1].upper()] = vec
                current = None
    return setups, faces


def placed_back(placement, q):
    """The workpiece point a setup's placement puts at q."""
    at, zax, xax = placement
    yax = (zax[1] * xax[2] - zax[2] * xax[1], zax[2] * xax[0] - zax[0] * xax[2], zax[0] * xax[1] - zax[1] * xax[0])
    d = sub(q, at)
    return tuple(sum(d[k] * ax[k] for k in range(3)) for ax in (xax, yax, zax))


def turned_back(placement, v):
    """A direction in the setup's frame taken back to the workpiece."""
    return placed_back((( 0.0, 0.0, 0.0), placement[1], placement[2]), v)


def ir_feed_moves(ir_path, setups):
    """The IR's feed moves (linear, arc), each with its end (and an arc's
    centre at its height) and the face's normal, in workpiece coordinates."""
    # Which setup each move is in: by the `moves` block it follows.
    blocks = []
    with open(ir_path) as f:
        for n, line in enumerate(f, 1):
            m = MOVES_RE.match(line)
            if m:
                blocks.append((n, m.group(1)))
    out = []
    for mv in toolpath_ir.read_moves(ir_path):
        if mv["kind"] not in ("linear", "arc"):
            continue
        setup = [s for n, s in blocks if n < mv["line"]][-1]
        at, zax, xax = setups[setup]
        yax = (zax[1] * xax[2] - zax[2] * xax[1], zax[2] * xax[0] - zax[0] * xax[2], zax[0] * xax[1] - zax[1] * xax[0])

        def back(q):
            d = sub(q, at)
            return tuple(sum(d[k] * ax[k] for k in range(3)) for ax in (xax, yax, zax))
        normal = (xax[2], yax[2], zax[2])
        entry = {"kind": mv["kind"], "to": back(mv["to"]), "normal": normal, "line": mv["line"],
                 "text": mv["text"]}
        if mv["kind"] == "arc":
            if mv["plane"] != "xy":
                raise SystemExit("check-indexed: an arc outside the XY plane (IR line %d)" % mv["line"])
            entry["centre"] = back((mv["centre"][0], mv["centre"][1], mv["start"][2]))
            entry["middle"] = back(arc_middle(mv["start"], mv["to"], mv["centre"], mv["ccw"], mv["sweep"], "xy"))
        out.append(entry)
    return out


def canon_feed_moves(canon_path, chain, work_offset, faces):
    """The canonical feed moves in workpiece coordinates, with the tool's
    direction; and the problems of turns made below the top of z. A
    re-clamp message (`re-clamp the workpiece with its -Z face up`) places
    the workpiece as that face's setup does from there on."""
    out, problems = [], []
    clamping = IDENTITY

    def back(tip, k):
        return placed_back(clamping, tip), turned_back(clamping, k)
    offset = (0.0, 0.0, 0.0)
    angles = {"a": 0.0, "b": 0.0, "c": 0.0}
    z = None
    plane = "xy"
    at = (0.0, 0.0, 0.0)  # where the tool is, program coordinates
    with open(canon_path) as f:
        for n, line in enumerate(f, 1):
            msg = MESSAGE_RE.search(line)
            if msg and RECLAMP_RE.search(msg.group(1)):
                face = RECLAMP_RE.search(msg.group(1)).group(1)
                if face not in faces:
                    problems.append("canon line %d: a re-clamp with face %s up, which no setup has" % (n, face))
                else:
                    clamping = faces[face]
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
            middle = None
            if m.group(1) == "ARC_FEED":
                # The plane's first and second axes, then its normal.
                e1, e2, c1, c2, turn, e3, a, b, c = args[:9]
                to, centre = toolpath_ir.world((e1, e2, e3), plane), toolpath_ir.world((c1, c2, e3), plane)
                sweep = toolpath_ir.arc_sweep(toolpath_ir.local(at, plane), (e1, e2), (c1, c2), turn > 0) + \
                    2 * math.pi * (abs(int(turn)) - 1)
                middle = arc_middle(at, to, (c1, c2), turn > 0, sweep, plane)
            else:
                to, centre = tuple(args[:3]), None
                a, b, c = args[3:6]
            new = {"a": a, "b": b, "c": c}
            if new != angles:
                top = add(to, offset)[2]
                if z is None or abs(z - chain.z_top) > TOL_MM or abs(top - chain.z_top) > TOL_MM:
                    problems.append("canon line %d: the table turns with the tool at machine z %s, not at the top "
                                    "of its travel %g: %s" % (n, z, chain.z_top, line.strip()))
                angles = new
            z = add(to, offset)[2]
            at = to
            if m.group(1) == "STRAIGHT_TRAVERSE":
                continue
            tip, k = back(*chain.to_workpiece(add(to, offset), angles, work_offset))
            entry = {"to": tip, "axis": k, "text": "canon line %d: %s" % (n, line.strip())}
            if centre:
                entry["centre"] = back(*chain.to_workpiece(add(centre, offset), angles, work_offset))[0]
                entry["middle"] = back(*chain.to_workpiece(add(middle, offset), angles, work_offset))[0]
            out.append(entry)
    return out, problems


def run_with_offset(program, work, work_offset):
    """rs274's canonical moves of the program with G54 set to the work offset
    (mm; rs274's variables file is in inches): (canon path, None) or (None, why)."""
    with open(os.path.join(work, "vars.var"), "w") as f:
        f.write("5220 1\n")
        for k, v in enumerate(work_offset):
            f.write("%d %.9f\n" % (5221 + k, v / 25.4))
    return check_rs274.run_rs274(program, work)



def compare_feed_moves(want, made, problems):
    """The IR's feed moves (ir_feed_moves) against those the program made,
    in order: ends, and arcs' centres and middles, within TOL_MM; the tool's
    direction within TOL_DEG of the face's normal. Appends to `problems` and
    returns the largest differences (mm, deg)."""
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
    return worst_mm, worst_deg


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--program", required=True)
    ap.add_argument("--ir", required=True)
    ap.add_argument("--machine", required=True, help="the machine's TOML file (table-table, head-table, head-head)")
    ap.add_argument("--work-offset", required=True)
    args = ap.parse_args()
    work_offset = tuple(float(v) for v in args.work_offset.split(","))
    chain = Chain(args.machine)
    with tempfile.TemporaryDirectory() as work:
        canon, why = run_with_offset(args.program, work, work_offset)
        if not canon:
            print("FAIL: " + why)
            return 1
        setups, faces = read_setups(args.ir)
        made, problems = canon_feed_moves(canon, chain, work_offset, faces)
    want = ir_feed_moves(args.ir, setups)
    worst_mm, worst_deg = compare_feed_moves(want, made, problems)
    if problems:
        for p in problems[:5]:
            print("FAIL: " + p)
        return 1
    print("ok: %d feed moves on %d faces match through the machine's kinematics (largest %.4f mm, %.4f deg)" %
          (len(want), len({w["normal"] for w in want}), worst_mm, worst_deg))
    return 0


if __name__ == "__main__":
    sys.exit(main())
