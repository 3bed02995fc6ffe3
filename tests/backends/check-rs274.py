#!/usr/bin/env python3
"""Runs LinuxCNC's rs274 interpreter on stepnc's rs274 programs and checks
that the moves it makes are the planned ones.

For each input (a STEP-NC file or IR text) the script compiles the toolpath
IR and the rs274 program (as the options say), writes a tool table for
rs274 (in inches, as that tool reads it, with zero length offsets), runs
`rs274 -g` with a strict arc tolerance, and compares its canonical moves
(STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED) with the IR's moves, one by
one, within 0.001 mm:

  * rapids: a run of consecutive rapids is compared by where it ends (a
    backend may split a rapid, e.g. XY then Z after a tool change);
  * feed moves: end point, and feed rate within the program's rounding;
  * arcs: end point, centre, direction and number of turns;
  * cubic splines (G5, which rs274 reports as NURBS_FEED without
    coordinates): each NURBS_FEED is matched with its G5 block in the
    program, in order; its end point is the block's X Y, and the Bézier its
    I J P Q give must stay within the target's 0.01 mm of the IR's line
    (the line is a chord of the curve the spline follows).
The first motion of the program and the first after each tool change
must move Z alone (up to the clearance height): where the tool is then is
the machine's business, so X and Y only move once it is up. Lathe programs
(G18 with G7 or G8) are compared the same way, in the XZ plane with feeds
per revolution (rs274 reports them as it reads X: a radius), without that
rule: a lathe's tool comes from its turret outside the stock.
Moves that go nowhere are left out on both sides. With canned cycles on,
the cycles' own rapids are the controller's: only the feed moves must match
(--cycles); with --no-cycles everything must.

Deposition programs (compiled with a --machine whose [deposition] table
gives LinuxCNC's output codes, docs/additive.md): the script reads that
table, follows the outputs in the canonical output (SET/CLEAR_MOTION_OUTPUT_BIT
for M62/M63, SET/CLEAR_AUX_OUTPUT_BIT for M64/M65, SET_MOTION/AUX_OUTPUT_VALUE
for M67/M68) and checks that at every motion the energy output is on exactly
when the IR's head is on, never during a rapid, and that the power and
powder outputs hold the IR's values whenever the energy is on.

Exit status 0 when every input matches, 1 otherwise (each difference is
printed with the IR move and the canonical line).
"""
import argparse
import fcntl
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib

import toolpath_ir
from toolpath_ir import arc_sweep, local, world

TOL = 1e-3

CANON_RE = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SET_FEED_RATE|NURBS_FEED|DWELL|SELECT_PLANE|"
                      r"START_SPEED_FEED_SYNC|STOP_SPEED_FEED_SYNCH|SET_MOTION_OUTPUT_BIT|CLEAR_MOTION_OUTPUT_BIT|"
                      r"SET_AUX_OUTPUT_BIT|CLEAR_AUX_OUTPUT_BIT|SET_MOTION_OUTPUT_VALUE|SET_AUX_OUTPUT_VALUE)"
                      r"\(([^)]*)\)")
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def deposition_outputs(extra):
    """The outputs of the --machine among `extra` that its [deposition] codes
    drive: {'energy': (kind, n), 'power': (kind, n), 'powder': ...}, kind
    'bit' or 'value'; None without a machine or a [deposition] table."""
    spec = next((a.split("=", 1)[1] for a in extra if a.startswith("--machine=")), None)
    if spec is None:
        return None
    path = spec if os.path.exists(spec) else os.path.join(REPO, "machines", spec + ".toml")
    with open(path, "rb") as f:
        table = tomllib.load(f).get("deposition")
    if not table:
        return None
    out = {}
    for key in ("energy_on", "power", "powder", "wire"):
        code = table.get(key, "")
        m = re.match(r"M6([2-5]) P(\d+)", code)
        if m:
            out[key.replace("_on", "")] = ("bit", int(m.group(2)))
        m = re.match(r"M6([78]) E(\d+)", code)
        if m:
            out[key] = ("value", int(m.group(2)))
    return out
CANON_PLANES = {"CANON_PLANE_XY": "xy", "CANON_PLANE_XZ": "zx", "CANON_PLANE_YZ": "yz"}
G5_RE = re.compile(r"^G5 X(\S+) Y(\S+) I(\S+) J(\S+) P(\S+) Q(\S+)")
SPLINE_TOL = 0.01
SWEEP_TOL = 0.005  # mm along an arc: the printed ends and the centre balanced between them


def g5_blocks(program):
    """The G5 blocks of a program, in order: (x, y, i, j, p, q)."""
    with open(program) as f:
        return [tuple(float(v) for v in m.groups()) for m in (G5_RE.match(line) for line in f) if m]


def canon_moves(path, program):
    out = []
    bits, values = {}, {}
    feed = 0.0
    synced = None
    splines = iter(g5_blocks(program))
    at = (0.0, 0.0, 0.0)
    plane = "xy"
    with open(path) as f:
        for n, line in enumerate(f, 1):
            m = CANON_RE.search(line)
            if not m:
                continue
            args = [a.strip() for a in m.group(2).split(",")]
            if m.group(1).endswith("OUTPUT_BIT"):
                bits[int(args[0])] = m.group(1).startswith("SET")
                continue
            if m.group(1).endswith("OUTPUT_VALUE"):
                values[int(args[0])] = float(args[1])
                continue
            if m.group(1) == "SELECT_PLANE":
                plane = CANON_PLANES[args[0]]
                continue
            if m.group(1) == "SET_FEED_RATE":
                feed = float(args[0])
                continue
            # G33: the moves until the sync stops advance K per revolution,
            # whatever F says; they are the IR's `role=thread` lines, their
            # feed per revolution the lead.
            if m.group(1) == "START_SPEED_FEED_SYNC":
                synced = float(args[0])
                continue
            if m.group(1) == "STOP_SPEED_FEED_SYNCH":
                synced = None
                continue
            if m.group(1) == "DWELL" and float(args[0]) == 0:
                continue  # G84 waits 0 s at the bottom: no wait
            if m.group(1) == "DWELL":
                out.append({"kind": "dwell", "to": at, "time": float(args[0]),
                            "text": "canon line %d: %s" % (n, line.strip())})
                continue
            if m.group(1) == "NURBS_FEED":
                x, y, i, j, p, q = next(splines)
                out.append({"kind": "linear", "to": (x, y, at[2]), "feed": feed,
                            "bezier": ((at[0], at[1]), (at[0] + i, at[1] + j), (x + p, y + q), (x, y)),
                            "text": "canon line %d: %s (G5 X%g Y%g I%g J%g P%g Q%g)" % (n, line.strip(), x, y, i, j, p,
                                                                                       q)})
                at = out[-1]["to"]
                continue
            if m.group(1) == "ARC_FEED":
                # The plane's first and second axes, then its normal (XZ: z, x, y).
                e1, e2, c1, c2, turn, e3 = (float(a) for a in args[:6])
                # An arc that ends where it starts is a whole turn: the
                # sweep says what the controller cuts.
                sweep = arc_sweep(local(at, plane), (e1, e2), (c1, c2), turn > 0) + 2 * math.pi * (abs(int(turn)) - 1)
                out.append({"kind": "arc", "to": world((e1, e2, e3), plane), "plane": plane, "centre": (c1, c2),
                            "ccw": turn > 0, "turns": abs(int(turn)) - 1, "sweep": sweep, "feed": feed,
                            "text": "canon line %d: %s" % (n, line.strip())})
            else:
                kind = "rapid" if m.group(1) == "STRAIGHT_TRAVERSE" else "linear"
                move = {"kind": kind, "to": tuple(float(a) for a in args[:3]),
                        "text": "canon line %d: %s" % (n, line.strip())}
                if kind == "linear":
                    move["feed"] = feed if synced is None else synced
                out.append(move)
            at = out[-1]["to"]
            out[-1]["outputs"] = (dict(bits), dict(values))
    return out


def head_problems(ir, canon, outputs):
    """Each motion whose energy output is not the IR head's, a rapid with the
    energy on, or a bead made with other power or powder outputs than the
    IR's (moves compared one by one, those that go nowhere left out)."""
    problems = []
    a = [m for m in normalise(ir, False)]
    b = [m for m in normalise(canon, False)]
    kind, n = outputs["energy"]
    for i, (x, y) in enumerate(zip(a, b)):
        bits, values = y.get("outputs", ({}, {}))
        on = bits.get(n, False) if kind == "bit" else values.get(n, 0.0) > 0
        want = x.get("head", {}).get("energy", False)
        why = None
        if on and y["kind"] == "rapid":
            why = "the energy is on during a rapid"
        elif on != want:
            why = "the energy output is %s, the IR's head %s" % ("on" if on else "off", "on" if want else "off")
        elif on:
            for key, ir_key in (("power", "power"), ("powder", "powder_feed"), ("wire", "wire_feed")):
                if key in outputs and ir_key in x.get("head", {}):
                    got = values.get(outputs[key][1])
                    if got is None or abs(got - x["head"][ir_key]) > 1e-3:
                        why = "%s output %s, the IR's %s %g" % (key, got, ir_key, x["head"][ir_key])
        if why:
            problems.append("move %d: %s\n    IR:    %s\n    %s" % (i + 1, why, x["text"], y["text"]))
            if len(problems) >= 5:
                break
    return problems


MOTION_RE = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|NURBS_FEED)\(([^)]*)\)")


def is_lathe_program(program):
    """A lathe program (docs/turning.md): its preamble selects G18 and a lathe's X mode."""
    with open(program) as f:
        return any(re.match(r"G18 G[78]\b", line) for line in f)


def clearance_problems(path):
    """Each first motion, of the program or after a CHANGE_TOOL, that moves X or Y."""
    problems = []
    at = (0.0, 0.0)
    first = "the program start"
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if "CHANGE_TOOL(" in line:
                first = "the tool change at canon line %d" % n
                continue
            m = MOTION_RE.search(line)
            if not m:
                continue
            args = [a.strip() for a in m.group(2).split(",")]
            to = (float(args[0]), float(args[1])) if m.group(1) != "NURBS_FEED" else None
            if first and (to is None or abs(to[0] - at[0]) > TOL or abs(to[1] - at[1]) > TOL):
                problems.append("canon line %d: the first motion after %s moves X or Y, not Z alone up to the "
                                "clearance height: %s" % (n, first, line.strip()))
            first = None
            if to is not None:
                at = to
    return problems


def bezier_strays(bezier, a, b):
    """How far the cubic Bézier strays from the segment a-b (sampled)."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = bezier
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    worst = 0.0
    for k in range(1, 16):
        t = k / 16.0
        u = 1 - t
        px = u * u * u * x0 + 3 * u * u * t * x1 + 3 * u * t * t * x2 + t * t * t * x3
        py = u * u * u * y0 + 3 * u * u * t * y1 + 3 * u * t * t * y2 + t * t * t * y3
        s = max(0.0, min(1.0, ((px - a[0]) * dx + (py - a[1]) * dy) / length2)) if length2 > 0 else 0.0
        worst = max(worst, ((px - a[0] - s * dx) ** 2 + (py - a[1] - s * dy) ** 2) ** 0.5)
    return worst


def close(a, b):
    return all(abs(x - y) <= TOL for x, y in zip(a, b))


def prints_as_one(a, b):
    """Whether two points print as one with the program's 4 decimals (the IR
    text carries the same 4)."""
    return all(round(x, 4) == round(y, 4) for x, y in zip(a, b))


def same_centre(x, y):
    """Whether the program's arc y has the IR arc x's centre. An IR arc whose
    ends are not as far from its centre (a path offset for tool deflection
    changing along it) is written with the centre moved onto the bisector of
    its ends (backends/common/IsoEmitter.cpp, geom::balancedCentre): that
    centre is taken when the two arcs then pass within the tolerance of each
    other halfway along."""
    if close(x["centre"], y["centre"]):
        return True
    (ax, ay), (bx, by) = local(x["start"], x["plane"])[:2], local(x["to"], x["plane"])[:2]
    (cx, cy), (dx, dy) = x["centre"], (bx - ax, by - ay)
    length = math.hypot(dx, dy)
    if length == 0:
        return False
    along = ((cx - (ax + bx) / 2) * dx + (cy - (ay + by) / 2) * dy) / length
    balanced = (cx - along * dx / length, cy - along * dy / length)
    if not close(balanced, y["centre"]):
        return False

    def halfway(centre):
        a0 = math.atan2(ay - centre[1], ax - centre[0])
        mid = a0 + (x["sweep"] / 2) * (1 if x["ccw"] else -1)
        r = (math.dist((ax, ay), centre) + math.dist((bx, by), centre)) / 2
        return (centre[0] + r * math.cos(mid), centre[1] + r * math.sin(mid))
    return close(halfway(x["centre"]), halfway(y["centre"]))


def normalise(moves, feeds_only):
    """Leaves out moves that go nowhere and keeps the end of each run of rapids."""
    out = []
    at = None
    for mv in moves:
        if mv["kind"] == "arc" and "start" in mv and mv["sweep"] < math.pi and \
                prints_as_one(local(mv["start"], mv["plane"])[:2], local(mv["to"], mv["plane"])[:2]):
            # An IR arc whose ends print as one point is written as the line
            # it is within the last decimal: a controller reads an arc over its
            # start as a whole circle (backends/common/Words.h, arcPrintsClosed).
            # Ends a last decimal apart print apart, and stay an arc.
            mv = dict(mv, kind="linear")
        if mv["kind"] not in ("arc", "dwell") and at is not None and close(mv["to"], at):
            continue
        at = mv["to"]
        if feeds_only and mv["kind"] == "rapid":
            continue
        if out and mv["kind"] == "rapid" and out[-1]["kind"] == "rapid":
            out[-1] = mv
        else:
            out.append(mv)
    return out


def compare(ir, canon, feeds_only, feed_tol):
    a = normalise(ir, feeds_only)
    b = normalise(canon, feeds_only)
    problems = []
    for i, (x, y) in enumerate(zip(a, b)):
        why = None
        if x["kind"] != y["kind"]:
            why = "kind %s != %s" % (x["kind"], y["kind"])
        elif not close(x["to"], y["to"]):
            why = "end point differs"
        elif x["kind"] == "dwell" and abs(x["time"] - y["time"]) > 0.0006:
            why = "dwell %.3f s != %.3f s" % (x["time"], y["time"])
        elif x["kind"] not in ("rapid", "dwell") and abs(x["feed"] - y["feed"]) > feed_tol:
            why = "feed %.3f != %.3f" % (x["feed"], y["feed"])
        elif x["kind"] == "arc" and x["plane"] != y["plane"]:
            why = "arc in the %s plane, the IR's in the %s plane" % (y["plane"].upper(), x["plane"].upper())
        elif x["kind"] == "arc" and (not same_centre(x, y) or x["ccw"] != y["ccw"]
                                     or x["turns"] != y["turns"]):
            why = "arc centre, direction or turns differ"
        elif x["kind"] == "arc" and abs(x["sweep"] - y["sweep"]) * x["radius"] > SWEEP_TOL:
            why = "the arc turns %.3f deg, the IR's %.3f deg" % (math.degrees(y["sweep"]), math.degrees(x["sweep"]))
        elif "bezier" in y and i > 0 and bezier_strays(y["bezier"], a[i - 1]["to"], x["to"]) > SPLINE_TOL:
            why = "the spline strays %.4f mm from the line" % bezier_strays(y["bezier"], a[i - 1]["to"], x["to"])
        if why:
            problems.append("move %d: %s\n    IR:    %s\n    %s" % (i + 1, why, x["text"], y["text"]))
            if len(problems) >= 5:
                break
    if len(a) != len(b) and len(problems) < 5:
        problems.append("the IR has %d moves, rs274 made %d" % (len(a), len(b)))
    return problems, len(a)


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def run_rs274(ngc_path, workdir):
    """Runs LinuxCNC's rs274 on a program: (the canonical moves file, None),
    or (None, why) when rs274 rejects it. The tool table has every T number
    the program calls, length 0, with the diameter its header gives (a lathe
    insert's: twice its corner radius; 0.25 in otherwise), in inches, and the
    orientation (Q) it gives; arcs are checked to 0.001 mm."""
    canon_path = os.path.join(workdir, "prog.canon")
    tools, diameters, orientations = {}, {}, {}
    with open(ngc_path) as f:
        for line in f:
            m = re.match(r"\(T(\d+) .*diameter ([0-9.]+) mm", line)
            if m:
                diameters[int(m.group(1))] = float(m.group(2)) / 25.4
            m = re.match(r"\(T(\d+) .*corner radius ([0-9.]+) mm", line)
            if m:
                diameters[int(m.group(1))] = 2 * float(m.group(2)) / 25.4
            m = re.match(r"\(T(\d+) .*orientation Q(\d)", line)
            if m:
                orientations[int(m.group(1))] = int(m.group(2))
            for t in re.findall(r"\bT(\d+)\b", line.split("(")[0]):
                tools[int(t)] = None
    for t in tools:
        tools[t] = diameters.get(t, 0.25)
    table = os.path.join(workdir, "tools.tbl")
    with open(table, "w") as f:
        for t, d in sorted(tools.items()):
            q = " Q%d" % orientations[t] if t in orientations else ""
            f.write("T%d P%d Z0 D%.6f%s ;\n" % (t, t, d, q))
    ini = os.path.join(workdir, "strict.ini")
    with open(ini, "w") as f:
        f.write("[RS274NGC]\nCENTER_ARC_RADIUS_TOLERANCE_MM = 0.001\n")
    # rs274 keeps its tool data in a memory-mapped file (/tmp/.tool.mmap) shared by every rs274
    # running on the machine: two at once read each other's tools. One at a time.
    with open("/tmp/stepnc-rs274.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        r = run(["rs274", "-g", "-t", table, "-i", ini, "-v", os.path.join(workdir, "vars.var"), ngc_path,
                 canon_path], cwd=workdir, stdin=subprocess.DEVNULL)
    if r.returncode != 0:
        return None, "rs274 rejected the program (exit %d):\n%s%s" % (r.returncode, r.stdout, r.stderr)
    return canon_path, None


def check(stepnc, path, cycles, extra, workdir, program=None, target_opts=(), ir=None):
    base = os.path.join(workdir, "prog")
    ir_path, ngc_path = base + ".ir", base + ".ngc"
    if ir:
        ir_path = ir
    else:
        r = run([stepnc, "compile", path, "--emit=toolpath-ir", "-o", ir_path] + extra)
        if r.returncode != 0:
            return ["stepnc could not make the toolpath IR:\n" + r.stderr]
    if program:
        ngc_path = program
    else:
        opts = ([] if cycles else ["--no-cycles"]) + extra + ["--target-opt=" + o for o in target_opts]
        r = run([stepnc, "compile", path, "--target=rs274", "-o", ngc_path] + opts)
        if r.returncode != 0:
            return ["stepnc could not write the rs274 program:\n" + r.stderr]
    canon_path, error = run_rs274(ngc_path, workdir)
    if error:
        return [error]
    ir_moves, canon = toolpath_ir.read_moves(ir_path), canon_moves(canon_path, ngc_path)
    problems, n = compare(ir_moves, canon, cycles, 0.05 + 1e-9)
    outputs = deposition_outputs(extra)
    deposits = any("head" in m for m in ir_moves)
    if deposits and not outputs:
        problems.append("the IR deposits, and no --machine with a [deposition] table of LinuxCNC codes says which "
                        "outputs to follow")
    elif deposits and "energy" not in outputs:
        problems.append("the machine's energy_on is no M62-M65 output code this check follows")
    elif deposits:
        problems += head_problems(ir_moves, canon, outputs)
    # A lathe's tool starts each step from outside the stock in X and Z
    # (verify-toolpaths checks that its rapids meet no stock); a mill's
    # goes up along Z alone first.
    if not is_lathe_program(ngc_path):
        problems += clearance_problems(canon_path)
    if not problems:
        print("ok: %s%s: %d moves match" % (os.path.basename(path), "" if cycles else " (--no-cycles)", n))
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stepnc", required=True, help="the stepnc executable")
    ap.add_argument("--no-cycles", action="store_true", help="compile with --no-cycles and compare every move")
    ap.add_argument("--program", help="check this program against the (single) input's IR instead of "
                    "compiling one (to show that the check can fail)")
    ap.add_argument("--ir", help="with --program: the toolpath IR the program was written from (a phase's, "
                    "from compile --emit=toolpath-ir with several --machine), instead of compiling the input's")
    ap.add_argument("--target-opt", action="append", default=[], help="a target option for the program only "
                    "(the IR is the same): nose-compensation=controller")
    ap.add_argument("inputs", nargs="+")
    args, extra = ap.parse_known_args()
    failed = False
    for path in args.inputs:
        with tempfile.TemporaryDirectory() as work:
            problems = check(args.stepnc, path, not args.no_cycles, extra, work, args.program, args.target_opt,
                             args.ir)
        for p in problems:
            print("FAIL: %s: %s" % (path, p))
        failed = failed or bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
