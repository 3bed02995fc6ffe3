#!/usr/bin/env python3
"""An independent check that a pocket's vertical corner radii are left: the
toolpath IR's feed moves below the pocket's top, sampled every 0.1 mm, each
tool centre checked against the pocket's profile as a polygon (written on
the command line, counter-clockwise) with its convex corners rounded by the
corner radius, with plain geometry here (no code of stepnc's):

  * every centre keeps at least the tool radius from every edge of the
    polygon (less the tolerance): no gouge into a straight wall;
  * in the zone of a rounded corner (between its two tangent points), every
    centre lies within (corner radius - tool radius) of the fillet's centre
    (plus the tolerance): the fillet is left, not cut to the tool's radius.

It prints, per workingstep, the number of centres checked, how close the
tool came to each fillet (the smallest margin) and its offences, and exits 1
on any offence.

    check-fillets.py IR --polygon "x,y x,y ..." --radius R --top Z
"""
import argparse
import math
import re
import sys

sys.path.insert(0, __import__("os").path.join(__import__("os").path.dirname(__file__), "..", "..", "backends"))
import toolpath_ir  # noqa: E402

STEP = 0.1


def samples(move):
    """Points along a feed move, every STEP mm, the end included."""
    a, b = move["start"], move["to"]
    if move["kind"] == "linear":
        n = max(1, int(math.dist(a, b) / STEP))
        return [tuple(a[i] + (b[i] - a[i]) * k / n for i in range(3)) for k in range(n + 1)]
    c, r, sweep = move["centre"], move["radius"], move["sweep"]
    start = math.atan2(a[1] - c[1], a[0] - c[0])
    sign = 1 if move["ccw"] else -1
    n = max(1, int(r * sweep / STEP))
    return [(c[0] + r * math.cos(start + sign * sweep * k / n), c[1] + r * math.sin(start + sign * sweep * k / n),
             a[2] + (b[2] - a[2]) * k / n) for k in range(n + 1)]


def segment_distance(p, a, b):
    ab = (b[0] - a[0], b[1] - a[1])
    t = ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / (ab[0] ** 2 + ab[1] ** 2)
    t = min(1.0, max(0.0, t))
    return math.dist(p[:2], (a[0] + t * ab[0], a[1] + t * ab[1]))


def fillets(poly, radius):
    """Each convex corner of the counter-clockwise polygon: the fillet's
    centre, its tangent points and the directions of the edges in and out."""
    out = []
    for i, v in enumerate(poly):
        p, q = poly[i - 1], poly[(i + 1) % len(poly)]
        d1 = ((v[0] - p[0]) / math.dist(p, v), (v[1] - p[1]) / math.dist(p, v))
        d2 = ((q[0] - v[0]) / math.dist(v, q), (q[1] - v[1]) / math.dist(v, q))
        if d1[0] * d2[1] - d1[1] * d2[0] <= 1e-12:
            continue  # a reflex corner (or straight): the material's corner, sharp
        n1, n2 = (-d1[1], d1[0]), (-d2[1], d2[0])  # inward normals
        # (c - v) . n1 = radius and (c - v) . n2 = radius
        det = n1[0] * n2[1] - n1[1] * n2[0]
        cx = (radius * n2[1] - n1[1] * radius) / det
        cy = (n1[0] * radius - radius * n2[0]) / det
        c = (v[0] + cx, v[1] + cy)
        t1 = (c[0] - radius * n1[0], c[1] - radius * n1[1])
        t2 = (c[0] - radius * n2[0], c[1] - radius * n2[1])
        out.append({"corner": v, "centre": c, "t1": t1, "t2": t2, "d1": d1, "d2": d2, "margin": math.inf})
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ir")
    ap.add_argument("--polygon", required=True)
    ap.add_argument("--radius", type=float, required=True)
    ap.add_argument("--top", type=float, required=True)
    ap.add_argument("--tol", type=float, default=0.01)
    args = ap.parse_args()
    poly = [tuple(float(c) for c in xy.split(",")) for xy in args.polygon.split()]
    steps, current, tool_radius = [], None, {}
    text = open(args.ir).read()
    for m in re.finditer(r"^\s*tool (%\S+) .*?diameter=([0-9.]+)mm", text, re.M):
        tool_radius[m.group(1)] = float(m.group(2)) / 2
    # The moves of each workingstep, with its tool.
    step_of_line = {}
    for n, line in enumerate(text.splitlines(), 1):
        if m := re.match(r"^\s*workingstep (@\S+)", line):
            current = [m.group(1), None]
            steps.append(current)
        elif (m := re.match(r"^\s*moves tool=(%\S+)", line)) and current:
            current[1] = m.group(1)
        step_of_line[n] = current
    bad = 0
    per_step = {}
    for move in toolpath_ir.read_moves(args.ir):
        if move["kind"] not in ("linear", "arc"):
            continue
        step = step_of_line[move["line"]]
        r = tool_radius[step[1]]
        stats = per_step.setdefault(step[0], {"centres": 0, "fillets": fillets(poly, args.radius), "r": r, "bad": 0})
        for p in samples(move):
            if p[2] >= args.top - 1e-9:
                continue
            stats["centres"] += 1
            wall = min(segment_distance(p, poly[i - 1], poly[i]) for i in range(len(poly)))
            if wall < r - args.tol:
                bad += 1
                stats["bad"] += 1
                if bad <= 10:
                    print("GOUGE %s line %d: centre (%.4f, %.4f) %.4f mm from a wall, tool radius %.4f"
                          % (step[0], move["line"], p[0], p[1], wall, r))
            for f in stats["fillets"]:
                c = f["centre"]
                past1 = (p[0] - f["t1"][0]) * f["d1"][0] + (p[1] - f["t1"][1]) * f["d1"][1] > 0
                before2 = (p[0] - f["t2"][0]) * f["d2"][0] + (p[1] - f["t2"][1]) * f["d2"][1] < 0
                if not (past1 and before2):
                    continue
                margin = (args.radius - r) - math.dist(p[:2], c)
                f["margin"] = min(f["margin"], margin)
                if margin < -args.tol:
                    bad += 1
                    stats["bad"] += 1
                    if bad <= 10:
                        print("FILLET %s line %d: centre (%.4f, %.4f) cuts the %.1f mm fillet at (%g, %g) by %.4f mm"
                              % (step[0], move["line"], p[0], p[1], args.radius, f["corner"][0], f["corner"][1],
                                 -margin))
    for name, stats in per_step.items():
        margins = ", ".join("(%g,%g) %s" % (f["corner"][0], f["corner"][1],
                                           "not reached" if f["margin"] == math.inf else "%.3f" % f["margin"])
                            for f in stats["fillets"])
        print("%s: tool radius %.3f, %d centres; closest to each fillet (mm to spare): %s; offences %d"
              % (name, stats["r"], stats["centres"], margins, stats["bad"]))
    print("ok" if not bad else "%d offences" % bad)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
