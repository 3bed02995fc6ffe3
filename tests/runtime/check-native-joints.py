#!/usr/bin/env python3
"""Checks the joints a native motion file (version 4) gives at each
segment's end: through the machine's forward kinematics (written in
tests/backends/check-indexed.py from the machine file alone) they put the
tool tip at the segment's end point (the work offset added) and, on a
segment that tilts the tool, the tool along its end axis: within 0.001 mm
and 0.001 deg.

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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--motion", required=True)
    ap.add_argument("--machine", required=True)
    ap.add_argument("--work-offset", required=True)
    args = ap.parse_args()
    offset = tuple(float(v) for v in args.work_offset.split(","))
    chain = check_indexed.Chain(args.machine)
    import tomllib
    with open(args.machine, "rb") as f:
        names = list(tomllib.load(f)["axes"].keys())
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
            tip, k = chain.to_workpiece((values["x"], values["y"], values["z"]),
                                        {a: values.get(a, 0.0) for a in "abc"}, offset)
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
