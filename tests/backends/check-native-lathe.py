#!/usr/bin/env python3
"""Checks stepnc's native motion for a lathe (docs/native-format.md, version 3)
against the toolpath IR it was planned from, by playing it independently of
stepnc's player.

For each input the script compiles the toolpath IR and the native motion on
the machine given, reads the machine's spindle from its TOML file, and plays
every segment at the machine's cycle (and at least 8 points a segment). At
each sample it checks:

  * the path: the point (z, x) is within the machine's path tolerance
    (+1e-6 mm) of a move of the toolpath IR, the moves taken in order (the
    first from the last one matched that the point is on);
  * feed per revolution: on lines and arcs at feed, the path speed is never
    above the move's feed per revolution times the spindle's speed then
    (linear in time over the segment, as the format says), and at the
    segment's cruise at least 97 % of it, unless an axis held the speed,
    or the spindle's acceleration did (it changes speed at 90 % of the
    machine's rate or more over the segment), or the planner gave a run of
    short pieces one profile at the least of their feeds (the segment's
    speed limit is below its own feed);
  * constant surface speed: on cuts of a step at constant surface speed,
    the spindle is within 3 % of v / (2 pi r), held between the step's
    limit (and the machine's) and the machine's minimum, at the tool's
    radius r;
  * threads: a segment marked `sync index` is a thread pass of the IR (role
    thread), keeps the step's spindle speed, and at its cruise moves at
    exactly its lead times that speed.
Over the whole file: the spindle's speed is continuous from segment to
segment (from 0 at the start) and changes no faster than the machine's
spindle acceleration.

Exit status 0 when every input passes, 1 otherwise (each failure printed
with its segment).
"""
import argparse
import importlib.util
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import toolpath_ir  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SPEC = importlib.util.spec_from_file_location("native_play", os.path.join(HERE, "..", "..", "tools", "native-play.py"))
play = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(play)
PLAY_KEYS = play.KEYS | {"spindle", "sync"}


def machine_file(spec, root):
    if os.path.exists(spec):
        return spec
    return os.path.join(root, "machines", spec + ".toml")


def step_spindles(ir_path):
    """Per IR line number of a move: the step's (constant rev/min, surface speed mm/min or None, limit rev/min)."""
    out, current = {}, None
    number = re.compile(r"(-?[0-9.]+)")
    with open(ir_path) as f:
        for n, line in enumerate(f, 1):
            code = line.split(";")[0].strip()
            if code.startswith("moves "):
                m = re.search(r"spindle=(-?[0-9.]+)rev/min", code)
                current = [float(m.group(1)) if m else 0.0, None, None]
            elif code.startswith("state ") and "surface_speed=" in code and current is not None:
                current[1] = float(number.search(code.split("surface_speed=")[1]).group(1))
                m = re.search(r"spindle_max=([0-9.]+)rev/min", code)
                current[2] = float(m.group(1)) if m else None
            elif re.match(r"(rapid|linear|arc|dwell)\s", code) and current is not None:
                out[n] = tuple(current)
    return out


def distance_to(move, z, x):
    """Distance from the point (z, x) to an IR move in the XZ half plane."""
    if move["kind"] == "arc":
        cz, cx = move["centre"]  # the ZX plane's coordinates: (z, x)
        a = toolpath_ir.local(move["start"], "zx")
        start_angle = math.atan2(a[1] - cx, a[0] - cz)
        angle = math.atan2(x - cx, z - cz)
        turned = (angle - start_angle) if move["ccw"] else (start_angle - angle)
        turned %= 2 * math.pi
        if turned <= move["sweep"] + 1e-12:
            return abs(math.hypot(z - cz, x - cx) - move["radius"])
        b = toolpath_ir.local(move["to"], "zx")
        return min(math.hypot(z - a[0], x - a[1]), math.hypot(z - b[0], x - b[1]))
    (x0, _, z0), (x1, _, z1) = move["start"], move["to"]
    dz, dx = z1 - z0, x1 - x0
    length2 = dz * dz + dx * dx
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((z - z0) * dz + (x - x0) * dx) / length2))
    return math.hypot(z0 + t * dz - z, x0 + t * dx - x)


def check(args, stp):
    failures = []
    root = os.path.join(HERE, "..", "..")
    with open(machine_file(args.machine, root), "rb") as f:
        spindle_spec = tomllib.load(f).get("spindle", {})
    accel = float(spindle_spec.get("acceleration", 0)) or math.inf
    lowest, highest = float(spindle_spec.get("min_speed", 0)), float(spindle_spec.get("max_speed", math.inf))
    with tempfile.TemporaryDirectory() as tmp:
        ir, motion = os.path.join(tmp, "part.ir"), os.path.join(tmp, "part.motion")
        runs = [(["--emit=toolpath-ir"], ir)]
        if args.motion:
            motion = args.motion
        else:
            runs.append((["--target=native", "--machine=" + args.machine], motion))
        for extra, out in runs:
            run = subprocess.run([args.stepnc, "compile", stp, *extra, "-o", out], capture_output=True, text=True)
            if run.returncode != 0:
                return [f"stepnc compile {' '.join(extra)} failed:\n{run.stderr}"]
        moves = [m for m in toolpath_ir.read_moves(ir) if m["kind"] != "dwell"]
        spindles = step_spindles(ir)
        lines = [l.split() for l in open(motion, encoding="utf-8") if l.strip() and not l.lstrip().startswith(";")]
    if lines[0] != ["STEPNC-MOTION", "3"]:
        return [f"not a version 3 native file: {' '.join(lines[0])}"]
    head = {w[0]: w[1:] for w in lines[1:8]}
    if head.get("axes") != ["z", "x", "y"]:
        return ["the axes line is not 'axes z x y'"]
    cycle, tolerance = float(head["cycle_time"][0]), float(head["tolerance"][0])
    at = [float(v) for v in head["start"]]
    body = lines[7:-1]
    cursor, n_before = 0, 0.0
    worst_path, worst_css, worst_rate, samples, threads = 0.0, 0.0, 0.0, 0, 0
    lowest_ratio = math.inf
    for index, words in enumerate(body, 1):
        f, key = {}, None
        for w in words[1:]:
            if w in PLAY_KEYS:
                key, f[w] = w, []
            else:
                f[key].append(w)
        kind = words[0]
        seg = (kind, at, f)
        ph = [float(v) for v in f["phases"][1:]]
        phases = list(zip(ph[0::2], ph[1::2]))
        duration = sum(d for d, _ in phases)
        n0, n1 = (float(v) for v in f["spindle"])
        sync = f["sync"][0] == "index"
        feed = float(f["programmed_feed"][0])
        where = f"segment {index} ({kind} to {' '.join(f['to'])})"
        if abs(n0 - n_before) > 1e-6 * max(1.0, abs(n0)):
            failures.append(f"{where}: the spindle jumps from {n_before} to {n0} rev/min")
        if duration > 0:
            worst_rate = max(worst_rate, abs(n1 - n0) / duration)
            if abs(n1 - n0) > accel * duration * (1 + 1e-6) + 1e-6:
                failures.append(f"{where}: the spindle changes {abs(n1 - n0):.1f} rev/min in {duration:.4f} s, "
                                f"faster than {accel} rev/min/s")
        n_before = n1
        v_limit = float(f["limits"][0])
        limited = f["limited_by"][0]
        count = max(8, int(duration / cycle))
        for k in range(count + 1):
            t = duration * k / count
            s, v, a = 0.0, float(f["v0"][0]), float(f["a0"][0])
            rest = t
            for d, j in phases:
                d = max(0.0, min(rest, d))
                s, v, a, rest = s + v * d + a * d * d / 2 + j * d ** 3 / 6, v + a * d + j * d * d / 2, a + j * d, rest - d
            p = play.point(seg, min(s, float(f["length"][0])))
            z, x = p[0], p[1]
            samples += 1
            # The first programmed move from where the tool was that it is
            # on (moves are taken in order; a later pass may cross the same
            # point), else the nearest.
            best, best_at = math.inf, cursor
            for m in range(max(0, cursor - 2), min(len(moves), cursor + 60)):
                d = distance_to(moves[m], z, x)
                if d <= tolerance + 1e-6:
                    best, best_at = d, m
                    break
                if d < best:
                    best, best_at = d, m
            cursor = best_at
            worst_path = max(worst_path, best)
            if best > tolerance + 1e-6:
                failures.append(f"{where}: at t {t:.4f} s the tool is at z {z:.4f} x {x:.4f}, {best:.4f} mm from "
                                f"the toolpath (tolerance {tolerance})")
                break
            move = moves[cursor]
            n = n0 + (n1 - n0) * (t / duration if duration > 0 else 0)
            if kind in ("line", "arc") and feed > 0 and move.get("per_rev"):
                allowed = move["feed"] * abs(n) / 60
                if v > allowed * (1 + 1e-6) + 1e-9:
                    failures.append(f"{where}: {v * 60:.3f} mm/min at {abs(n):.1f} rev/min is more than "
                                    f"{move['feed']} mm/rev ({move['text']})")
                    break
                spindle_bound = duration > 0 and abs(n1 - n0) / duration >= 0.9 * accel
                own_cap = v_limit >= feed * (1 - 1e-9)  # not a run of short pieces planned at the least of their caps
                if (limited == "feed" and own_cap and not spindle_bound and abs(a) < 1e-9
                        and v >= v_limit * (1 - 1e-9) and allowed > 0):
                    lowest_ratio = min(lowest_ratio, v / allowed)
                    if v < 0.97 * allowed:
                        failures.append(f"{where}: at cruise {v * 60:.3f} mm/min, below 97 % of {move['feed']} "
                                        f"mm/rev x {abs(n):.1f} rev/min")
                        break
                constant, css, limit = spindles[move["line"]]
                if css is not None and not sync:
                    cap = min(limit if limit else highest, highest)
                    r = abs(x)
                    wanted = min(css / (2 * math.pi * r), cap) if r > 1e-9 else cap
                    wanted = max(wanted, lowest)
                    off = abs(abs(n) - wanted) / wanted
                    worst_css = max(worst_css, off)
                    if off > 0.03:
                        failures.append(f"{where}: the spindle at {abs(n):.1f} rev/min at radius {r:.4f}, where the "
                                        f"surface speed asks {wanted:.1f}")
                        break
            if sync:
                if k == count // 2 and move["text"].find("role=thread") < 0:  # at its middle: its ends touch others
                    failures.append(f"{where}: synchronised, but not on a thread pass ({move['text']})")
                    break
                constant = spindles[move["line"]][0]
                if n0 != n1 or abs(n0 - constant) > 1e-9:
                    failures.append(f"{where}: a thread pass at {n0}..{n1} rev/min, not the step's {constant}")
                    break
                if abs(a) < 1e-9 and v >= v_limit * (1 - 1e-9):
                    wanted = move["feed"] * abs(n0) / 60
                    if abs(v - wanted) > 1e-6 * wanted:
                        failures.append(f"{where}: a thread pass at {v * 60:.4f} mm/min, not lead {move['feed']} x "
                                        f"{abs(n0)} rev/min")
                        break
        threads += sync
        at = [float(v) for v in f["to"]]
    print(f"{os.path.basename(stp)}: {len(body)} segments, {samples} samples: path within {worst_path:.6f} mm "
          f"of the toolpath IR; cruise at {lowest_ratio * 100 if lowest_ratio < math.inf else 100:.2f} % or more of "
          f"the feed per revolution, never above; spindle within {worst_css * 100:.2f} % of the surface speed, "
          f"changing at most {worst_rate:.1f} rev/min/s; {threads} thread pass segments synchronised")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stepnc", required=True)
    parser.add_argument("--machine", default="lathe-2axis")
    parser.add_argument("--motion", help="check this native file (planned from the one input) instead of compiling one")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    failed = False
    for stp in args.files:
        failures = check(args, stp)
        for message in failures[:20]:
            print(f"{stp}: {message}")
        failed |= bool(failures)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
