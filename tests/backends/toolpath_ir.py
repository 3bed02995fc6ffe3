"""The moves of a toolpath IR file (stepnc compile --emit=toolpath-ir), as the
backend checkers compare programs with them."""
import importlib.util
import math
import os
import re

MOVE_RE = re.compile(r"^\s*(rapid|linear|arc|dwell)\s+(.*)$")
ATTR_RE = re.compile(r"(\w+)=(\([^)]*\)|\S+)")
STATE_RE = re.compile(r"^\s*state\s+(.*)$")


def point(text):
    """'(1.0000,2.0000,3.0000)mm' -> (1.0, 2.0, 3.0)."""
    return tuple(float(v) for v in text.split(")")[0].strip("(").split(","))


PLANES = {"xy": (0, 1, 2), "zx": (2, 0, 1), "yz": (1, 2, 0)}


def local(p, plane):
    """A point in an arc plane's coordinates: its first and second axes, then
    the normal (XY: x y z; ZX: z x y; YZ: y z x), as stepnc and LinuxCNC's
    canonical ARC_FEED order them."""
    return tuple(p[k] for k in PLANES[plane])


def world(q, plane):
    """Back from an arc plane's coordinates."""
    p = [0.0, 0.0, 0.0]
    for v, k in zip(q, PLANES[plane]):
        p[k] = v
    return tuple(p)


def plane_of(normal):
    """The plane an IR arc `normal` names, and whether it points the plane's way."""
    for name, k in (("xy", 2), ("zx", 1), ("yz", 0)):
        if abs(abs(normal[k]) - 1) <= 1e-9:
            return name, normal[k] > 0
    raise ValueError("an arc normal along none of x, y and z: %r" % (normal,))


def arc_sweep(start, end, centre, ccw):
    """The angle from start to end about centre (radians, in (0, 2 pi]); end over start is a whole turn."""
    if math.dist(start[:2], end[:2]) <= 1e-9:
        return 2 * math.pi
    a = math.atan2(start[1] - centre[1], start[0] - centre[0])
    b = math.atan2(end[1] - centre[1], end[0] - centre[0])
    angle = (b - a) if ccw else (a - b)
    while angle <= 0:
        angle += 2 * math.pi
    while angle > 2 * math.pi:
        angle -= 2 * math.pi
    return angle


def read_moves(path):
    """Every move of every `moves` block (those of its canned cycles in place),
    in order, each a dict: kind (rapid, linear, arc, dwell), start and to (x,
    y, z; the first move starts at the origin, as the program model has it),
    feed (mm/min, feed moves only; a lathe's feed per revolution in mm/rev,
    with per_rev set), line (in the file) and text; arcs also
    plane ('xy', 'zx', 'yz'), centre (in the plane's coordinates: x, y in XY),
    ccw (seen from the plane's normal), turns, radius and sweep (radians,
    full turns included); dwells their time (s), where the tool is. A move
    that gives its tool axis (5-axis) has it as axis."""
    out = []
    pos = (0.0, 0.0, 0.0)
    # A deposition head's state: energy on or off, its power, powder, wire.
    head = {}
    with open(path) as f:
        for n, line in enumerate(f, 1):
            code = line.split(";")[0]
            st = STATE_RE.match(code)
            if st:
                attrs = dict(ATTR_RE.findall(st.group(1)))
                if "energy" in attrs:
                    head["energy"] = attrs["energy"] == "on"
                for key, unit in (("power", "W"), ("powder_feed", "g/min"), ("wire_feed", "mm/min")):
                    if key in attrs:
                        head[key] = float(attrs[key].replace(unit, ""))
                continue
            m = MOVE_RE.match(code)
            if not m:
                continue
            attrs = dict(ATTR_RE.findall(m.group(2)))
            if m.group(1) == "dwell":
                out.append({"kind": "dwell", "start": pos, "to": pos, "line": n, "text": code.strip(),
                            "time": float(attrs["time"].replace("s", ""))})
                continue
            move = {"kind": m.group(1), "start": pos, "to": point(attrs["to"]), "line": n, "text": code.strip()}
            if head:
                move["head"] = dict(head)
            if "axis" in attrs:
                move["axis"] = point(attrs["axis"])
            if "feed" in attrs:
                move["feed"] = float(attrs["feed"].replace("mm/min", ""))
            elif "feed_per_rev" in attrs:
                move["feed"] = float(attrs["feed_per_rev"].replace("mm/rev", ""))
                move["per_rev"] = True
            if move["kind"] == "arc":
                plane, positive = plane_of(point(attrs["normal"])) if "normal" in attrs else ("xy", True)
                centre = local(point(attrs["center"]), plane)[:2]
                ccw = (attrs["dir"] == "ccw") == positive
                turns = int(attrs.get("turns", "0"))
                start, end = local(pos, plane), local(move["to"], plane)
                move.update(plane=plane, centre=centre, ccw=ccw, turns=turns, radius=math.dist(start[:2], centre),
                            sweep=arc_sweep(start, end, centre, ccw) + 2 * math.pi * turns)
            pos = move["to"]
            out.append(move)
    return out


def load_script(name, file, here=os.path.dirname(os.path.abspath(__file__))):
    """Another checker of this folder as a module (their file names have
    dashes, which import cannot take)."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(here, file))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
