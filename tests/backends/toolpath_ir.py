"""The moves of a toolpath IR file (stepnc compile --emit=toolpath-ir), as the
backend checkers compare programs with them."""
import math
import re

MOVE_RE = re.compile(r"^\s*(rapid|linear|arc|dwell)\s+(.*)$")
ATTR_RE = re.compile(r"(\w+)=(\([^)]*\)|\S+)")


def point(text):
    """'(1.0000,2.0000,3.0000)mm' -> (1.0, 2.0, 3.0)."""
    return tuple(float(v) for v in text.split(")")[0].strip("(").split(","))


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
    feed (mm/min, feed moves only), line (in the file) and text; arcs also
    centre (x, y), ccw, turns, radius and sweep (radians, full turns
    included); dwells their time (s), where the tool is."""
    out = []
    pos = (0.0, 0.0, 0.0)
    with open(path) as f:
        for n, line in enumerate(f, 1):
            code = line.split(";")[0]
            m = MOVE_RE.match(code)
            if not m:
                continue
            attrs = dict(ATTR_RE.findall(m.group(2)))
            if m.group(1) == "dwell":
                out.append({"kind": "dwell", "start": pos, "to": pos, "line": n, "text": code.strip(),
                            "time": float(attrs["time"].replace("s", ""))})
                continue
            move = {"kind": m.group(1), "start": pos, "to": point(attrs["to"]), "line": n, "text": code.strip()}
            if "feed" in attrs:
                move["feed"] = float(attrs["feed"].replace("mm/min", ""))
            if move["kind"] == "arc":
                centre = point(attrs["center"])[:2]
                ccw = attrs["dir"] == "ccw"
                turns = int(attrs.get("turns", "0"))
                move.update(centre=centre, ccw=ccw, turns=turns, radius=math.dist(pos[:2], centre),
                            sweep=arc_sweep(pos, move["to"], centre, ccw) + 2 * math.pi * turns)
            pos = move["to"]
            out.append(move)
    return out
