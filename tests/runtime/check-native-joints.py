#!/usr/bin/env python3
"""Checks the joints a native motion file (version 4 or 5) gives at each
segment's end: through the machine's forward kinematics (written in
tests/backends/check-indexed.py from the machine file alone, or, for the
linear tripod, below) they put the tool tip at the segment's end point (the
work offset added) and, on a segment that tilts the tool, the tool along
its end axis: within 0.001 mm and 0.001 deg.

  check-native-joints.py --motion F.motion --machine M.toml --work-offset X,Y,Z
"""
import argparse
import importlib.util
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("check_indexed", os.path.join(HERE, "..", "backends", "check-indexed.py"))
check_indexed = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_indexed)


AXIS_DIRECTIONS = {"a": (1.0, 0.0, 0.0), "b": (0.0, 1.0, 0.0), "c": (0.0, 0.0, 1.0)}


def turned(v, direction, deg):
    """v turned right-handed by deg about the unit direction (Rodrigues)."""
    t = math.radians(deg)
    c, s = math.cos(t), math.sin(t)
    k = direction
    dot = sum(a * b for a, b in zip(k, v))
    cross = (k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0])
    return tuple(v[i] * c + cross[i] * s + k[i] * dot * (1 - c) for i in range(3))


class Tripod:
    """The linear-tripod solver's machine (docs/five-axis.md, "A
    parallel-kinematic machine"), from its machine file alone: the platform's
    centre is the lower point at the strut length from the three slider
    joints moved in by the platform's radius, found here by two linear
    equations (the spheres' differences) giving x and y in terms of z and a
    quadratic in z; the tip hangs the tool's length below it; then the
    table's turns are undone, outermost first."""

    def __init__(self, path, data):
        kin = data["kinematics"]
        p = kin["parameters"]
        self.joints = kin["joints"]
        reach = p["base_radius"] - p["platform_radius"]
        self.guides = [(reach * math.cos(math.radians(p["first_guideway"] + 120 * i)),
                        reach * math.sin(math.radians(p["first_guideway"] + 120 * i))) for i in range(3)]
        self.strut, self.tool = p["strut_length"], p["tool_length"]
        self.table = [(self.joints[3], AXIS_DIRECTIONS[self.joints[3]],
                       (p["tilt_pivot_x"], p["tilt_pivot_y"], p["tilt_pivot_z"])),
                      (self.joints[4], AXIS_DIRECTIONS[self.joints[4]],
                       (p["turn_pivot_x"], p["turn_pivot_y"], p["turn_pivot_z"]))]

    def to_workpiece(self, values, work_offset):
        (x1, y1), (x2, y2), (x3, y3) = self.guides
        s1, s2, s3 = (values[n] for n in self.joints[:3])
        # |P - C_i|^2 = L^2 less the same for C_1: linear in P,
        # 2 (C_i - C_1) . P = |C_i|^2 - |C_1|^2, i = 2, 3. Solved for x, y
        # with z kept: x = ax + bx z, y = ay + by z.
        def row(xi, yi, si):
            return (2 * (xi - x1), 2 * (yi - y1), 2 * (si - s1),
                    (xi * xi + yi * yi + si * si) - (x1 * x1 + y1 * y1 + s1 * s1))
        a1, b1, c1, r1 = row(x2, y2, s2)
        a2, b2, c2, r2 = row(x3, y3, s3)
        det = a1 * b2 - a2 * b1
        ax, bx = (r1 * b2 - r2 * b1) / det, (-c1 * b2 + c2 * b1) / det
        ay, by = (a1 * r2 - a2 * r1) / det, (-a1 * c2 + a2 * c1) / det
        # |P - C_1|^2 = L^2 as a quadratic in z.
        ux, uy = ax - x1, ay - y1
        qa = bx * bx + by * by + 1
        qb = 2 * (ux * bx + uy * by - s1)
        qc = ux * ux + uy * uy + s1 * s1 - self.strut * self.strut
        disc = qb * qb - 4 * qa * qc
        if disc < 0:
            return None, None
        z = (-qb - math.sqrt(disc)) / (2 * qa)  # the lower: the platform hangs below the sliders
        tip, k = (ax + bx * z, ay + by * z, z - self.tool), (0.0, 0.0, 1.0)
        for name, direction, pivot in self.table:
            tip = tuple(p + q for p, q in zip(pivot, turned(tuple(a - b for a, b in zip(tip, pivot)), direction,
                                                            -values[name])))
            k = turned(k, direction, -values[name])
        return tuple(a - b for a, b in zip(tip, work_offset)), k


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--motion", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--work-offset", required=True)
    args = ap.parse_args()
    offset = tuple(float(v) for v in args.work_offset.split(","))
    import tomllib
    with open(args.machine, "rb") as f:
        data = tomllib.load(f)
    names = list(data["axes"].keys())
    if data["kinematics"].get("solver") == "linear-tripod":
        tripod = Tripod(args.machine, data)
        names = tripod.joints

        def workpiece(values):
            return tripod.to_workpiece(values, offset)
    else:
        chain = check_indexed.Chain(args.machine)

        def workpiece(values):
            return chain.to_workpiece((values["x"], values["y"], values["z"]),
                                      {a: values.get(a, 0.0) for a in "abc"}, offset)
    worst_mm, worst_deg, count, problems = 0.0, 0.0, 0, []
    with open(args.motion) as f:
        for n, line in enumerate(f, 1):
            words = line.split()
            if not words or words[0] not in ("line", "arc", "blend", "dwell") or "joints" not in words:
                continue
            to = tuple(float(v) for v in words[2:5])
            at = words.index("tool")
            axis = tuple(float(v) for v in words[at + 4:at + 7])
            j = words.index("joints")
            joints = [float(v) for v in words[j + 2:j + 2 + int(words[j + 1])]]
            values = dict(zip(names, joints))
            tip, k = workpiece(values)
            if tip is None:
                problems.append("line %d: the struts cannot meet at those sliders" % n)
                continue
            mm = math.dist(tip, to)
            cos = max(-1.0, min(1.0, sum(p * q for p, q in zip(k, axis))))
            deg = math.degrees(math.acos(cos))
            worst_mm, worst_deg = max(worst_mm, mm), max(worst_deg, deg)
            count += 1
            if (mm > 1e-3 or deg > 1e-3) and len(problems) < 5:
                problems.append("line %d: the joints put the tip %.4f mm and the tool %.4f deg off" % (n, mm, deg))
    if not count:
        problems.append("no segment gives its joints")
    for p in problems:
        print("FAIL: " + p)
    if problems:
        return 1
    print("ok: %d segments' joints put the tool where they end (largest %.4f mm, %.4f deg)" % (count, worst_mm, worst_deg))
    return 0


if __name__ == "__main__":
    sys.exit(main())
