#!/usr/bin/env python3
"""Checks the flanks a program leaves on a boss whose walls lean in.

Reads an RS274 program (as stepnc writes it: absolute XYZ, G2/G3 with I J in
the XY plane, millimetres), takes the feed moves of one workingstep (from the
comment naming it to the next tool change or program end), and measures, in
sections across each flank of a rectangular boss, what material the levels
leave on the flank: at heights along the flank, the distance from the flank
(offset by the side allowance) to the nearest tool body swept along the
level. A tool moving along a flank sweeps, across it, its silhouette: a
rectangle of the tool's diameter from its tip up, its lower corners rounded
by the corner radius. The flank's material is left uncut where that distance
is positive (the ridge between levels, measured along the flank's normal to
the first body), gouged where it is negative.

Written from the geometry alone, independently of stepnc's generator and
verifier. Prints the largest ridge and the deepest gouge and fails when the
ridge exceeds the scallop height or the gouge the tolerance.

  check-sloped-flanks.py PROGRAM --start TEXT --foot X0,Y0,X1,Y1 --foot-z Z
      --top-z Z --slope DEG --radius R --corner RC [--allowance A]
      [--scallop H] [--tol T]
"""
import argparse
import bisect
import math
import re
import sys


def parse_moves(path, start):
    """Feed moves (lists of (x, y, z) points, arcs as chords) from the
    comment containing `start` to the next tool change or program end."""
    words = re.compile(r"([A-Z])\s*([-+]?[0-9]*\.?[0-9]+)")
    pos = [0.0, 0.0, 0.0]
    motion = 0
    taking = False
    levels = {}  # z -> list of 2D segments
    for raw in open(path, encoding="ascii"):
        line = raw.strip()
        if not taking:
            if start in line:
                taking = True
            continue
        code = re.sub(r"\(.*?\)", "", line).upper()
        if (levels and re.search(r"\bM0?6\b", code)) or re.search(r"\bM(2|30)\b", code):
            break
        ws = words.findall(code)
        if not ws:
            continue
        new = list(pos)
        ij = [0.0, 0.0]
        moved = False
        for letter, value in ws:
            v = float(value)
            if letter == "G" and v in (0, 1, 2, 3):
                motion = int(v)
            elif letter in "XYZ":
                new["XYZ".index(letter)] = v
                moved = True
            elif letter in "IJ":
                ij["IJ".index(letter)] = v
        if not moved:
            continue
        if motion in (1, 2, 3) and abs(new[2] - pos[2]) < 1e-6:
            segs = levels.setdefault(round(new[2], 4), [])
            if motion == 1:
                segs.append(((pos[0], pos[1]), (new[0], new[1])))
            else:
                cx, cy = pos[0] + ij[0], pos[1] + ij[1]
                a0 = math.atan2(pos[1] - cy, pos[0] - cx)
                a1 = math.atan2(new[1] - cy, new[0] - cx)
                r = math.hypot(pos[0] - cx, pos[1] - cy)
                sweep = a1 - a0
                if motion == 3 and sweep <= 0:
                    sweep += 2 * math.pi
                if motion == 2 and sweep >= 0:
                    sweep -= 2 * math.pi
                n = max(1, int(abs(sweep) * r / 0.05))
                prev = (pos[0], pos[1])
                for k in range(1, n + 1):
                    a = a0 + sweep * k / n
                    p = (cx + r * math.cos(a), cy + r * math.sin(a))
                    segs.append((prev, p))
                    prev = p
        pos = new
    return levels


def crossing(seg, origin, normal, along):
    """Where the segment crosses the section line through `origin` along
    `normal`: the distance along `normal`, or None."""
    (ax, ay), (bx, by) = seg
    da = (ax - origin[0]) * along[0] + (ay - origin[1]) * along[1]
    db = (bx - origin[0]) * along[0] + (by - origin[1]) * along[1]
    if (da > 0) == (db > 0) or da == db:
        return None
    t = da / (da - db)
    x, y = ax + (bx - ax) * t, ay + (by - ay) * t
    return (x - origin[0]) * normal[0] + (y - origin[1]) * normal[1]


def body_distance(u, h, axis_u, tip, radius, corner):
    """Signed distance from (u, h) in the section to the tool's silhouette
    with its axis at axis_u, its tip at `tip` (negative inside)."""
    flat = radius - corner
    du = abs(u - axis_u)
    # The silhouette is the rectangle |du| <= flat, h >= tip + corner, grown by the corner radius.
    dx = max(du - flat, 0.0)
    dy = max(tip + corner - h, 0.0)
    if dx > 0 or dy > 0:
        return math.hypot(dx, dy) - corner
    return -min(flat - du + corner, h - tip)  # inside: the way out nearest


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("program")
    ap.add_argument("--start", required=True)
    ap.add_argument("--foot", required=True)
    ap.add_argument("--foot-z", type=float, required=True)
    ap.add_argument("--top-z", type=float, required=True)
    ap.add_argument("--slope", type=float, required=True)
    ap.add_argument("--radius", type=float, required=True)
    ap.add_argument("--corner", type=float, required=True)
    ap.add_argument("--allowance", type=float, default=0.0)
    ap.add_argument("--scallop", type=float, default=0.01)
    ap.add_argument("--tol", type=float, default=0.01)
    args = ap.parse_args()
    x0, y0, x1, y1 = (float(v) for v in args.foot.split(","))
    t = math.tan(math.radians(args.slope))
    cos_a, sin_a = math.cos(math.radians(args.slope)), math.sin(math.radians(args.slope))
    levels = parse_moves(args.program, args.start)
    if not levels:
        print(f"error: no feed moves after '{args.start}'")
        return 1
    r, rc, a = args.radius, args.corner, args.allowance
    lowest_tip = min(levels)
    # Below where the lowest level's corner touches the flank the tool
    # cannot reach (its corner leaves a fillet against the floor).
    reach = lowest_tip + rc - rc * sin_a + 0.02
    worst_ridge, worst_gouge, checked = -1e9, 1e9, 0
    faces = [  # (point on the foot line at the face's middle, outward normal, along)
        (((x0 + x1) / 2, y0), (0.0, -1.0), (1.0, 0.0)),
        (((x0 + x1) / 2, y1), (0.0, 1.0), (1.0, 0.0)),
        ((x0, (y0 + y1) / 2), (-1.0, 0.0), (0.0, 1.0)),
        ((x1, (y0 + y1) / 2), (1.0, 0.0), (0.0, 1.0)),
    ]
    for mid, normal, along in faces:
        half = (abs(x1 - x0) if along[0] else abs(y1 - y0)) / 2
        for share in (-0.4, 0.0, 0.4):
            origin = (mid[0] + along[0] * share * half, mid[1] + along[1] * share * half)
            # Each level's tool axis in this section: where its path crosses
            # the section nearest outside the flank at the level's height
            # (the path crosses again beyond the opposite flank, and paths
            # round other bosses further out).
            axes = []
            for z, segs in levels.items():
                wall = -(z - args.foot_z) * t
                us = [u for u in (crossing(s, origin, normal, along) for s in segs) if u is not None and u > wall]
                if us:
                    axes.append((min(us), z))
            axes.sort(key=lambda a: a[1])
            tips = [tip for _, tip in axes]

            def nearest(u, h):
                """The signed distance to the nearest tool body, from the
                levels whose tip is at most a corner (and a little) below h
                or a level above it (lower ones are further out)."""
                lo = bisect.bisect_left(tips, h - rc - 2.0)
                hi = bisect.bisect_right(tips, h + 2.0)
                return min((body_distance(u, h, au, tip, r, rc) for au, tip in axes[max(lo - 1, 0):hi]),
                           default=1e9)

            h = max(args.foot_z, reach)
            while h <= args.top_z - 0.02:
                # The flank at height h, offset by the allowance (normal to it).
                wall_u = -(h - args.foot_z) * t
                if abs(share) * half > half - (h - args.foot_z) * t - r:
                    h += 0.005
                    continue  # near the hip: the section does not cross the face alone
                u = wall_u + a / cos_a
                # How far the nearest tool body is: inside one, a gouge.
                d = nearest(u, h)
                worst_gouge = min(worst_gouge, d)
                if d > 0:
                    # The material left stands along the flank's normal (out
                    # and up) to the first body it meets: from the nearest
                    # body's distance, step by each point's (no body is
                    # nearer than that), until a body is reached.
                    thick = d
                    for _ in range(200):
                        step = nearest(u + thick * cos_a, h + thick * sin_a)
                        if step <= 1e-7:
                            break
                        thick += step
                    worst_ridge = max(worst_ridge, thick)
                checked += 1
                h += 0.005
    print(f"flanks: {len(levels)} levels, {checked} points from z={reach:.3f}, "
          f"largest ridge {max(worst_ridge, 0):.4f} mm, deepest gouge {max(-worst_gouge, 0):.4f} mm")
    bad = False
    if worst_ridge > args.scallop + args.tol / 10:
        print(f"error: a ridge of {worst_ridge:.4f} mm, more than the scallop height {args.scallop} mm")
        bad = True
    if -worst_gouge > args.tol:
        print(f"error: a gouge of {-worst_gouge:.4f} mm, more than the tolerance {args.tol} mm")
        bad = True
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
