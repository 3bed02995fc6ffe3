#!/usr/bin/env python3
"""Compares two plan dumps (stepnc-plan-dump) by what a change to the planner
may move: the plans' structure (segment kinds, moves, stops, what capped each
segment) must agree; numbers are compared as bits, and where they differ the
worst differences are reported in the units that matter: coordinates in mm,
segment durations in s, the clock at each segment's end relative to itself,
and speeds relative to the segment's top speed.

    bench/compare-plans.py BEFORE.txt AFTER.txt

Exit status 0 when the structure agrees (the numbers are for a person to
judge), 1 when it does not."""
import sys


def read(path):
    with open(path, encoding="utf-8") as f:
        return [line.split() for line in f]


def end_state(p):
    """Speed at the end and the top speed of a profile line's numbers."""
    v0, a0 = p[0], p[1]
    v, a, top = v0, a0, v0
    for k in range(7):
        d, j = p[2 + 2 * k], p[3 + 2 * k]
        if j != 0 and 0 < -a / j < d:  # the speed peaks inside the phase
            t = -a / j
            top = max(top, v + a * t + j * t * t / 2)
        v += a * d + j * d * d / 2
        a += j * d
        top = max(top, v)
    return v, top


def main(before, after):
    a, b = read(before), read(after)
    if len(a) != len(b):
        print(f"the plans differ in length: {len(a)} and {len(b)} lines")
        return 1
    structural = 0
    same_bits = True
    worst = {"coordinate (mm)": 0.0, "duration (s)": 0.0, "clock (relative)": 0.0, "speed (of top)": 0.0,
             "limit (relative)": 0.0}
    clock_a = clock_b = 0.0
    for la, lb in zip(a, b):
        if la[0] != lb[0] or len(la) != len(lb):
            structural += 1
            continue
        if la[0] == "#":
            clock_a = clock_b = 0.0
        if la == lb and la[0] != "P":
            continue
        if la[0] in ("#", "N"):
            structural += la != lb
            continue
        if la[0] == "S":
            same_bits = False
            if la[1] != lb[1]:
                structural += 1
                continue
            na, nb = [float.fromhex(x) for x in la[2:]], [float.fromhex(x) for x in lb[2:]]
            coordinates = list(range(6))  # start, end
            if la[1] == "2":  # blend: control points
                coordinates += list(range(7, 7 + 18))
            for i in coordinates:
                worst["coordinate (mm)"] = max(worst["coordinate (mm)"], abs(na[i] - nb[i]))
        elif la[0] == "I":
            if [la[i] for i in (4, 5, 6, 7, 8)] != [lb[i] for i in (4, 5, 6, 7, 8)]:
                structural += 1  # what capped it, its feed and moves, why it stops
            if la != lb:
                same_bits = False
                for i in (1, 2, 3):
                    x, y = float.fromhex(la[i]), float.fromhex(lb[i])
                    worst["limit (relative)"] = max(worst["limit (relative)"], abs(x - y) / max(abs(x), abs(y)))
        elif la[0] == "P":
            pa, pb = [float.fromhex(x) for x in la[1:]], [float.fromhex(x) for x in lb[1:]]
            da, db = sum(pa[2::2]), sum(pb[2::2])
            clock_a += da
            clock_b += db
            if la == lb:
                continue
            same_bits = False
            worst["duration (s)"] = max(worst["duration (s)"], abs(da - db))
            worst["clock (relative)"] = max(worst["clock (relative)"], abs(clock_a - clock_b) / max(clock_a, clock_b))
            (va, ta), (vb, tb) = end_state(pa), end_state(pb)
            top = max(ta, tb, 1e-300)
            worst["speed (of top)"] = max(worst["speed (of top)"], abs(pa[0] - pb[0]) / top, abs(va - vb) / top)
    print("structural differences:", structural)
    if same_bits:
        print("the same plans bit for bit")
    else:
        for name, value in worst.items():
            print(f"worst {name}: {value:.3g}")
    return 1 if structural else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
