#!/usr/bin/env python3
"""Plays a stepnc native motion file (docs/native-format.md) and prints the
tool position at every interpolation cycle: "t x y z" (s, mm). A reference
for controller writers; it trusts the file (stepnc's reader checks it)."""
import bisect
import math
import sys

KEYS = {"to", "center", "radius", "start_angle", "sweep", "dir", "ctrl", "length", "programmed_feed",
        "move", "next", "stop", "limits", "limited_by", "v0", "a0", "phases"}
GX = (0.0, -0.5384693101056831, 0.5384693101056831, -0.906179845938664, 0.906179845938664)
GW = (0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891, 0.2369268850561891)


def distance(v0, a0, phases, t):  # s(t): constant jerk per phase, from speed v0 and acceleration a0
    s, v, a = 0.0, v0, a0
    for d, j in phases:
        d = max(0.0, min(t, d))
        s, v, a, t = s + v * d + a * d * d / 2 + j * d ** 3 / 6, v + a * d + j * d * d / 2, a + j * d, t - d
    return s


def bezier(P, u):  # a Bezier curve of any degree at u
    n = len(P) - 1
    return [sum(math.comb(n, k) * u ** k * (1 - u) ** (n - k) * p[i] for k, p in enumerate(P)) for i in range(3)]


def speed(P, u):  # |B'(u)|
    return math.hypot(*bezier([[5 * (b - a) for a, b in zip(P[k], P[k + 1])] for k in range(5)], u))


def arclen(P, u0, u1):  # Gauss-Legendre with five points
    h, m = (u1 - u0) / 2, (u0 + u1) / 2
    return h * sum(w * speed(P, m + h * x) for x, w in zip(GX, GW))


def point(seg, s):
    kind, a, f = seg
    b, length = [float(x) for x in f["to"]], float(f["length"][0])
    if kind == "dwell":  # at rest where it is, for its phases' time
        return a
    if kind == "line":
        return [p + (q - p) * s / length for p, q in zip(a, b)]
    if kind == "arc":
        (cx, cy), r = map(float, f["center"]), float(f["radius"][0])
        sweep, phi0 = float(f["sweep"][0]), float(f["start_angle"][0])
        rise = (b[2] - a[2]) / sweep  # mm per radian
        theta = s / math.hypot(r, rise)
        phi = phi0 + (theta if f["dir"][0] == "ccw" else -theta)
        return [cx + r * math.cos(phi), cy + r * math.sin(phi), a[2] + rise * theta]
    c = [float(x) for x in f["ctrl"]]
    P = [a] + [c[i:i + 3] for i in range(0, 12, 3)] + [b]
    if "table" not in f:  # arc length at u = i/16; then Newton on arclen(u) = s within one interval
        f["table"] = [0.0]
        for i in range(16):
            f["table"].append(f["table"][-1] + arclen(P, i / 16, (i + 1) / 16))
    table = f["table"]
    i = min(max(bisect.bisect_right(table, s) - 1, 0), 15)
    u0, span = i / 16, table[i + 1] - table[i]
    u = u0 + (s - table[i]) / span / 16 if span > 0 else u0
    for _ in range(4):
        u = min(max(u - (table[i] + arclen(P, u0, u) - s) / speed(P, u), u0), u0 + 1 / 16)
    return bezier(P, u)


def main(path):
    lines = [l.split() for l in open(path, encoding="utf-8") if l.strip() and not l.lstrip().startswith(";")]
    if not lines or lines[0] not in (["STEPNC-MOTION", "1"], ["STEPNC-MOTION", "2"]):
        sys.exit(f"{path}: not a version 1 or 2 native motion file")
    head = {w[0]: w[1:] for w in lines[1:6]}
    cycle, at = float(head["cycle_time"][0]), [float(x) for x in head["start"]]
    fmt = lambda v: "0.000000" if f"{v:.6f}" == "-0.000000" else f"{v:.6f}"
    k, t0 = 0, 0.0  # the next sample k * cycle; the time the segment starts
    for words in lines[6:-1]:
        f, key = {}, None  # each keyword with the values that follow it
        for w in words[1:]:
            if w in KEYS:
                key, f[w] = w, []
            else:
                f[key].append(w)
        seg = (words[0], at, f)
        ph = [float(x) for x in f["phases"][1:]]
        phases = list(zip(ph[0::2], ph[1::2]))
        t1 = t0 + sum(d for d, _ in phases)
        while k * cycle < t1:
            p = point(seg, distance(float(f["v0"][0]), float(f["a0"][0]), phases, k * cycle - t0))
            print(fmt(k * cycle), *map(fmt, p))
            k += 1
        t0, at = t1, [float(x) for x in f["to"]]
    print(fmt(t0), *map(fmt, at))  # at rest at the end


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else sys.exit("usage: native-play.py FILE.motion"))
