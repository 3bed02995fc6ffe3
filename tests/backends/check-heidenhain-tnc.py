#!/usr/bin/env python3
"""Structural checker for the HEIDENHAIN TNC conversational (Klartext)
programs stepnc writes (backends/heidenhain-tnc). No Heidenhain checker is
packaged for Debian, so this script reads the program back the way the
control would, for the subset of Klartext the backend writes, and reports
what the control would reject or do differently:

  * frame: block numbers from 0, consecutive, on every line (the indented
    `Qnnn=` lines of a CYCL DEF are continuations of its block: the line
    before ends in `~`); `BEGIN PGM NAME MM` first and `END PGM NAME MM` last
    with the same name; `M30` (or `M2`) in the block before `END PGM`;
  * words: every block of a known form; coordinates signed, no exponent, no
    `-0`; `L` blocks made of X/Y/Z, R0/RL/RR, F or FMAX and one M function
    from a whitelist; `TOOL CALL n Z S..`; `BLK FORM 0.1 Z` then `0.2` with
    MIN below MAX; cycle 32 and cycle 200 with all their Q parameters; cycle
    247 (a clamping's datum, then Z alone first as after a TOOL CALL); cycle
    9 (`CYCL DEF 9.0 DWELL TIME`, then `CYCL DEF 9.1 DWELL t`, t > 0 s);
  * 5-axis: `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS` and `FUNCTION RESET
    TCPM` in turn, rotary words (A, B, C after X Y Z) only between them, no
    TOOL CALL between them, the rotary axes back at 0 at the reset, none
    left on at the end; 3+2: `CYCL DEF 7.0 DATUM SHIFT` with 7.1 X, 7.2 Y,
    7.3 Z in the next blocks, `PLANE SPATIAL SPA.. SPB.. SPC.. TURN FMAX`,
    `PLANE RESET STAY` and `PLANE RESET TURN FMAX`, every TURN right after
    the tool went up in machine coordinates (`L Z.. R0 FMAX M91`, the only
    M91 block, no move of the program's), Z alone first after a PLANE, no
    plane left tilted at the end (check-working-plane.py checks where the
    frames put the moves);
  * motion: the first after each TOOL CALL is an L block with Z alone (up
    to the clearance height: where the tool change left the tool is the
    machine's business, so X and Y only move once it is up); no motion
    before a TOOL CALL, no feed move without a feed or
    with the spindle stopped; a `C` needs a `CC` and the tracked position and
    the end as far from it within --arc-tol (default 0.001 mm); `CP` has IPA
    and DR of the same sign; `M99` needs a cycle 200 and the tool at or above
    its second set-up clearance (the security plane).

With --ir TOOLPATH.IR the moves the program makes (cycle 200 expanded as the
TNC manual describes it: README.md; its Q211 and cycle 9 as dwells) are also compared with the toolpath
IR's moves: runs of rapids by where they end, feed moves by end point and
feed, arcs also by direction, sweep and path (points at eighths of each
written arc within 0.005 mm of the IR's circle; an arc that keeps that
close to its chord may be a line). The moves that tilt the tool (under
FUNCTION TCPM) are check-tcp.py's, through the machine's kinematics.

Exit status 0 when clean, 1 listing each problem with its block number.
"""
import argparse
import math
import re
import sys

import toolpath_ir

NUM_SIGNED = r"[+-]\d+(?:\.\d+)?"
NUM_UNSIGNED = r"\d+(?:\.\d+)?"
M_ALLOWED = {0, 1, 2, 3, 4, 5, 7, 8, 9, 30, 91, 99}
TCPM_ON = "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS"
TCPM_OFF = "FUNCTION RESET TCPM"
CYCLE_200_Q = [200, 201, 206, 202, 210, 203, 204, 211]
END_TOL = 0.002   # a CP ends where the control turns the start: printed angle and pole
PATH_TOL = 0.005  # along arcs: printed endpoints, and poles moved on the grid to balance the radii
FEED_TOL = 0.5 + 1e-6  # feeds are printed as whole mm/min


class Problems:
    def __init__(self):
        self.items = []

    def add(self, where, text):
        self.items.append("%s: %s" % (where, text))


def signed(text, where, problems, what):
    """The value of a signed coordinate word's number, or None (reported)."""
    if not re.fullmatch(NUM_SIGNED, text):
        problems.add(where, "%s '%s' is not a signed decimal number (sign, digits, '.' decimals)" % (what, text))
        return None
    value = float(text)
    if value == 0 and text.startswith("-"):
        problems.add(where, "%s '%s' is a negative zero" % (what, text))
    return value


def unsigned(text, where, problems, what):
    if not re.fullmatch(NUM_UNSIGNED, text):
        problems.add(where, "%s '%s' is not an unsigned decimal number" % (what, text))
        return None
    return float(text)


def read_blocks(text, problems):
    """[(block number, first line's text, [continuation lines], line number)],
    reporting lines without a number and numbers out of sequence."""
    blocks = []
    expected = 0
    continuing = False
    if text and not text.endswith("\n"):
        problems.add("end of file", "the last line has no line end")
    for lineno, line in enumerate(text.split("\n")[:-1] if text.endswith("\n") else text.split("\n"), 1):
        if any(ord(c) > 126 or (ord(c) < 32 and c != "\t") for c in line) or "\t" in line:
            problems.add("line %d" % lineno, "characters other than printable ASCII")
        if line != line.rstrip():
            problems.add("line %d" % lineno, "trailing spaces")
        if continuing:
            if blocks:
                blocks[-1][2].append(line.strip())
            continuing = line.rstrip().endswith("~")
            continue
        m = re.fullmatch(r"(\d+) (\S.*)", line)
        if not m:
            problems.add("line %d" % lineno, "no block number: '%s'" % line)
            continue
        number = int(m.group(1))
        if number != expected:
            problems.add("block %d" % number, "block number %d where %d was due (line %d)" % (number, expected, lineno))
        expected = number + 1
        blocks.append((number, m.group(2), [], lineno))
        continuing = m.group(2).rstrip().endswith("~")
    if continuing:
        problems.add("end of file", "the last block ends in '~' (continued) but nothing follows")
    return blocks


class Machine:
    """What the control has after each block: position, pole, feed, spindle,
    defined cycle; and the motions it made (for --ir)."""

    def __init__(self, problems, arc_tol):
        self.p = problems
        self.arc_tol = arc_tol
        self.pos = [None, None, None]
        self.cc = None
        self.feed = None
        self.tool = None
        self.spindle = False
        self.cycle = None
        self.motions = []
        self.up_first = None  # the TOOL CALL whose first motion is still to come
        self.tcp = False  # FUNCTION TCPM on
        self.step_start = 0  # the first motion of the step (after its "* - NAME" block)
        self.abc = {}  # the rotary axes as last written
        # 3+2: the datum shift and the spatial angles in force (None: no
        # plane tilted), the face the last re-clamp message put up, whether
        # the tool went up in machine coordinates (M91: its Z) with nothing
        # moved since, and what each PLANE ... TURN turned with.
        self.shift = (0.0, 0.0, 0.0)
        self.plane = None
        self.reclamp = None
        self.retracted = None
        self.turns = []

    def need_tool(self, where, z_alone=False):
        if self.tool is None:
            self.p.add(where, "motion before any TOOL CALL")
        if self.up_first and not z_alone:
            self.p.add(where, "the first motion after the TOOL CALL at %s is not Z alone (up to the clearance "
                              "height before X and Y move)" % self.up_first)
        self.up_first = None

    def feed_move(self, where, feed):
        if feed is not None:
            self.feed = feed
        if self.feed is None:
            self.p.add(where, "feed move without a feed programmed since the TOOL CALL")
        if not self.spindle:
            self.p.add(where, "feed move with the spindle stopped (no M3/M4 since the TOOL CALL or a stop)")

    def m_function(self, where, m, before_motion):
        """M functions effective at the start of the block (before_motion) or
        at its end."""
        if before_motion and m in (3, 4):
            if self.tool is None:
                self.p.add(where, "M%d before any TOOL CALL" % m)
            self.spindle = True
        if not before_motion and m in (0, 1, 2, 5, 30):
            self.spindle = False

    def line(self, where, axes, rapid, feed):
        # An L block without coordinates ("L M30" in a program with no
        # motion) moves nothing: it needs no tool.
        if axes:
            self.need_tool(where, z_alone=list(axes) == ["Z"] and rapid)
        if not rapid and axes:
            self.feed_move(where, feed)
        target = list(self.pos)
        for k, v in axes.items():
            target["XYZ".index(k)] = v
        if axes:
            self.motions.append({"kind": "rapid" if rapid else "linear", "to": tuple(target),
                                 "feed": None if rapid else self.feed, "where": where, "tcp": self.tcp,
                                 "frame": self.frame()})
            self.retracted = None
        self.pos = target

    def arc(self, where, end_xy, ccw, feed):
        self.need_tool(where)
        self.feed_move(where, feed)
        if self.cc is None:
            self.p.add(where, "C without a CC before it")
            return
        if self.pos[0] is None or self.pos[1] is None:
            self.p.add(where, "C from an unknown position")
            return
        x = end_xy[0] if end_xy[0] is not None else self.pos[0]
        y = end_xy[1] if end_xy[1] is not None else self.pos[1]
        r1 = math.hypot(self.pos[0] - self.cc[0], self.pos[1] - self.cc[1])
        r2 = math.hypot(x - self.cc[0], y - self.cc[1])
        if abs(r1 - r2) > self.arc_tol + 1e-9:
            self.p.add(where, "arc radius from the start %.4f and to the end %.4f differ by %.4f mm (more than %g)"
                       % (r1, r2, abs(r1 - r2), self.arc_tol))
        if r1 < 1e-9:
            self.p.add(where, "arc of zero radius")
        a = (self.pos[0] - self.cc[0], self.pos[1] - self.cc[1])
        b = (x - self.cc[0], y - self.cc[1])
        sweep = turn_angle(a, b, ccw)
        if math.hypot(x - self.pos[0], y - self.pos[1]) < 1e-9:
            sweep = 2 * math.pi
        self.motions.append({"kind": "arc", "to": (x, y, self.pos[2]), "centre": self.cc, "ccw": ccw,
                             "sweep": sweep, "radius": r1, "feed": self.feed, "where": where,
                             "frame": self.frame()})
        self.retracted = None
        self.pos = [x, y, self.pos[2]]

    def polar_arc(self, where, ipa_deg, iz, ccw, feed):
        self.need_tool(where)
        self.feed_move(where, feed)
        if self.cc is None:
            self.p.add(where, "CP without a CC before it")
            return
        if None in self.pos:
            self.p.add(where, "CP from an unknown position")
            return
        a = math.radians(ipa_deg)
        rx, ry = self.pos[0] - self.cc[0], self.pos[1] - self.cc[1]
        x = self.cc[0] + rx * math.cos(a) - ry * math.sin(a)
        y = self.cc[1] + rx * math.sin(a) + ry * math.cos(a)
        z = self.pos[2] + iz
        self.motions.append({"kind": "arc", "to": (x, y, z), "centre": self.cc, "ccw": ccw, "sweep": abs(a),
                             "radius": math.hypot(rx, ry), "feed": self.feed, "where": where,
                             "frame": self.frame()})
        self.retracted = None
        self.pos = [x, y, z]

    def frame(self):
        """What places the coordinates in force: (datum shift, spatial angles
        or None, the face the last re-clamp put up or None)."""
        return (self.shift, self.plane, self.reclamp)

    def call_cycle(self, where):
        """M99 at the end of an L block: cycle 200 at the position."""
        q = self.cycle
        if q is None:
            self.p.add(where, "M99 without a CYCL DEF 200 before it")
            return
        if None in self.pos:
            self.p.add(where, "M99 at an unknown position")
            return
        if not self.spindle:
            self.p.add(where, "cycle called with the spindle stopped")
        surface, clearance, depth = q[203], q[200], q[201]
        second = max(q[204], clearance)
        if self.pos[2] < surface + q[204] - 1e-6:
            self.p.add(where, "cycle called at Z%.4f, below its 2nd set-up clearance Z%.4f (the security plane): "
                              "the move to the hole is not safe" % (self.pos[2], surface + q[204]))
        x, y = self.pos[0], self.pos[1]
        bottom = surface + depth
        self.motions.append({"kind": "rapid", "to": (x, y, surface + clearance), "where": where})
        reached = surface
        k = 1
        while True:
            target = max(surface - q[202] * k, bottom) if q[202] < -depth else bottom
            if reached < surface:
                self.motions.append({"kind": "rapid", "to": (x, y, surface + clearance), "where": where})
                self.motions.append({"kind": "rapid", "to": (x, y, reached + clearance), "where": where})
            self.motions.append({"kind": "linear", "to": (x, y, target), "feed": q[206], "where": where,
                                 "frame": self.frame()})
            reached = target
            if target <= bottom + 1e-9:
                if q[211] > 0:
                    # Q211: the wait at the bottom of the hole.
                    self.motions.append({"kind": "dwell", "to": (x, y, target), "time": q[211], "where": where})
                break
            k += 1
        self.motions.append({"kind": "rapid", "to": (x, y, surface + second), "where": where})
        self.pos = [x, y, surface + second]
        # The feed the cycle used is not the program's: a feed move must state one again.
        self.feed = None


def turn_angle(a, b, ccw):
    angle = math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])
    if not ccw:
        angle = -angle
    if angle < 0:
        angle += 2 * math.pi
    return angle


def check_l(words, where, mach, problems, is_last_before_end):
    """An L block: X Y Z (signed, in order), under FUNCTION TCPM also A B C,
    R0/RL/RR, F<n> or FMAX, one M."""
    axes = {}
    order = "XYZABC"
    state = 0  # 0 axes, 1 after R, 2 after F, 3 after M
    rapid = False
    feed = None
    ms = []
    for w in words:
        m = re.fullmatch(r"([XYZABC])(.*)", w)
        if m and state == 0:
            axis = m.group(1)
            if axis in axes or (axes and order.index(axis) < order.index(list(axes)[-1])):
                problems.add(where, "axis %s repeated or out of X Y Z A B C order" % axis)
            if axis in "ABC" and not mach.tcp:
                problems.add(where, "rotary axis %s with FUNCTION TCPM off" % axis)
            v = signed(m.group(2), where, problems, ("rotary axis " if axis in "ABC" else "coordinate ") + axis)
            if v is not None:
                axes[axis] = v
            continue
        if w in ("R0", "RL", "RR") and state < 1:
            state = 1
            if w != "R0":
                problems.add(where, "radius compensation %s: stepnc writes tool-centre paths (R0)" % w)
            continue
        if w == "FMAX" and state < 2:
            rapid, state = True, 2
            continue
        m = re.fullmatch(r"F(.*)", w)
        if m and state < 2:
            feed = unsigned(m.group(1), where, problems, "feed")
            if feed is not None and feed <= 0:
                problems.add(where, "feed F%s is not positive" % m.group(1))
            state = 2
            continue
        m = re.fullmatch(r"M(\d+)", w)
        if m:
            state = 3
            n = int(m.group(1))
            if n not in M_ALLOWED:
                problems.add(where, "M%d is not among the M functions stepnc writes %s" % (n, sorted(M_ALLOWED)))
            ms.append(n)
            continue
        problems.add(where, "word '%s' is not valid here in an L block" % w)
    if len(ms) > 1:
        problems.add(where, "%d M functions in one block (stepnc writes one)" % len(ms))
    for n in ms:
        mach.m_function(where, n, before_motion=True)
    for axis in "ABC":
        if axis in axes:
            mach.abc[axis] = axes.pop(axis)
    if 91 in ms:
        # Up along Z in machine coordinates (no move of the program's): the
        # only M91 block stepnc writes.
        if not rapid or list(axes) != ["Z"]:
            problems.add(where, "M91 on a block other than 'L Z.. R0 FMAX M91'")
        mach.pos = [None, None, None]
        mach.retracted = axes.get("Z")
        return ms
    mach.line(where, axes, rapid, feed)
    for n in ms:
        mach.m_function(where, n, before_motion=False)
        if n == 99:
            mach.call_cycle(where)
    if (2 in ms or 30 in ms) and not is_last_before_end:
        problems.add(where, "program end M%d before the block before END PGM" % ms[0])
    return ms


def check_program(text, arc_tol):
    problems = Problems()
    mach = Machine(problems, arc_tol)
    blocks = read_blocks(text, problems)
    if not blocks:
        problems.add("file", "no blocks")
        return problems, mach
    begin = re.fullmatch(r"BEGIN PGM (\S+) (\S+)", blocks[0][1])
    end = re.fullmatch(r"END PGM (\S+) (\S+)", blocks[-1][1])
    if not begin:
        problems.add("block %d" % blocks[0][0], "the program does not start with BEGIN PGM NAME MM")
    if not end:
        problems.add("block %d" % blocks[-1][0], "the program does not end with END PGM NAME MM")
    if begin and end:
        if begin.group(1) != end.group(1):
            problems.add("block %d" % blocks[-1][0], "END PGM %s does not match BEGIN PGM %s"
                         % (end.group(1), begin.group(1)))
        if not re.fullmatch(r"[A-Za-z0-9_]+", begin.group(1)):
            problems.add("block 0", "program name '%s' has characters other than letters, digits and _"
                         % begin.group(1))
        for m, b in ((begin, blocks[0]), (end, blocks[-1])):
            if m.group(2) != "MM":
                problems.add("block %d" % b[0], "units '%s' where MM was expected" % m.group(2))
    ended = False
    blk01 = None
    last = len(blocks) - 1
    for i, (number, first, cont, lineno) in enumerate(blocks):
        where = "block %d" % number
        body = first
        if i in (0, last) and ((i == 0 and begin) or (i == last and end)):
            continue
        if re.match(r"(BEGIN|END) PGM", body):
            problems.add(where, "BEGIN PGM / END PGM inside the program")
            continue
        if body.startswith(";") or body.startswith("* - "):
            if body.startswith("* - "):
                mach.step_start = len(mach.motions)
            if body.rstrip().endswith("~"):
                problems.add(where, "a comment ending in '~' continues the block")
            m = re.search(r"^; MESSAGE: re-clamp the workpiece with its ([+-][XYZ]) face up", body)
            if m:
                mach.reclamp = m.group(1)
            continue
        if cont and not body.startswith("CYCL DEF 200 ") and not body.startswith("CYCL DEF 247 "):
            problems.add(where, "continuation lines after a block that is not a cycle definition")
        words = body.split()
        if ended:
            problems.add(where, "block after the program end (M30/M2)")
        if body.startswith("BLK FORM"):
            m = re.fullmatch(r"BLK FORM 0\.1 Z X(\S+) Y(\S+) Z(\S+)", body)
            m2 = re.fullmatch(r"BLK FORM 0\.2 X(\S+) Y(\S+) Z(\S+)", body)
            if m:
                blk01 = ([signed(v, where, problems, "BLK FORM coordinate") for v in m.groups()], number)
            elif m2:
                if blk01 is None or blk01[1] != number - 1:
                    problems.add(where, "BLK FORM 0.2 not right after a BLK FORM 0.1")
                else:
                    hi = [signed(v, where, problems, "BLK FORM coordinate") for v in m2.groups()]
                    for k, (a, b) in enumerate(zip(blk01[0], hi)):
                        if a is not None and b is not None and not a < b:
                            problems.add(where, "BLK FORM MIN %s%g is not below MAX %s%g" % ("XYZ"[k], a, "XYZ"[k], b))
                blk01 = None
            else:
                problems.add(where, "BLK FORM block not of the form 'BLK FORM 0.1 Z X.. Y.. Z..' / "
                                    "'BLK FORM 0.2 X.. Y.. Z..'")
            continue
        if blk01 is not None and blk01[1] == number - 1:
            problems.add(where, "BLK FORM 0.1 without its BLK FORM 0.2 after it")
            blk01 = None
        if body.startswith("CYCL DEF 7."):
            # A datum shift (3+2): the new datum in the untilted coordinates.
            if body == "CYCL DEF 7.0 DATUM SHIFT":
                parts = []
                for k, axis in enumerate("XYZ"):
                    nxt = blocks[i + 1 + k][1] if i + 1 + k < len(blocks) else ""
                    m = re.fullmatch(r"CYCL DEF 7\.%d %s(\S+)" % (k + 1, axis), nxt)
                    parts.append(signed(m.group(1), where, problems, "datum shift " + axis) if m else None)
                if None in parts:
                    problems.add(where, "CYCL DEF 7.0 DATUM SHIFT not followed by CYCL DEF 7.1 X.., 7.2 Y.. and 7.3 Z..")
                else:
                    if mach.plane is not None:
                        problems.add(where, "a datum shift with the working plane tilted (PLANE RESET first)")
                    mach.shift = tuple(parts)
                mach.pos = [None, None, None]
            elif not re.fullmatch(r"CYCL DEF 7\.[123] [XYZ]\S+", body) or \
                    blocks[i - int(body[11])][1] != "CYCL DEF 7.0 DATUM SHIFT":
                problems.add(where, "%s not in its place after CYCL DEF 7.0 DATUM SHIFT" % body)
            continue
        if body.startswith("PLANE "):
            # The working plane (3+2, PROCESSES.md C3).
            m = re.fullmatch(r"PLANE SPATIAL SPA(\S+) SPB(\S+) SPC(\S+) TURN FMAX", body)
            if not m and body not in ("PLANE RESET STAY", "PLANE RESET TURN FMAX"):
                problems.add(where, "PLANE not of the form 'PLANE SPATIAL SPA.. SPB.. SPC.. TURN FMAX', "
                                    "'PLANE RESET STAY' or 'PLANE RESET TURN FMAX'")
                continue
            if mach.tcp:
                problems.add(where, "PLANE with FUNCTION TCPM on")
            if body == "PLANE RESET STAY":
                if mach.plane is None:
                    problems.add(where, "PLANE RESET STAY with no working plane tilted")
                mach.plane = None
                continue
            if mach.retracted is None:
                problems.add(where, "the rotary axes turn (TURN) without the tool first up in machine coordinates "
                                    "(L Z.. R0 FMAX M91) and nothing moved since")
            angles = tuple(signed(v, where, problems, "spatial angle") for v in m.groups()) if m else None
            mach.turns.append({"where": where, "z": mach.retracted, "angles": angles})
            mach.plane = angles
            mach.pos = [None, None, None]
            mach.up_first = where
            continue
        if body.startswith("FUNCTION "):
            # Tool-centre-point control (PROCESSES.md C3), in the one form
            # stepnc writes.
            if body == TCPM_ON:
                if mach.tcp:
                    problems.add(where, "FUNCTION TCPM while it is on")
                mach.tcp = True
                # The whole step is check-tcp.py's, its clearance move too.
                for mv in mach.motions[mach.step_start:]:
                    mv["tcp"] = True
            elif body == TCPM_OFF:
                if not mach.tcp:
                    problems.add(where, "FUNCTION RESET TCPM while FUNCTION TCPM is off")
                turned = ["%s%g" % (a, v) for a, v in sorted(mach.abc.items()) if v != 0]
                if turned:
                    problems.add(where, "FUNCTION RESET TCPM with the rotary axes at %s, not 0" % " ".join(turned))
                mach.tcp = False
            else:
                problems.add(where, "FUNCTION block not of the form '%s' or '%s'" % (TCPM_ON, TCPM_OFF))
            continue
        if body.startswith("TOOL CALL"):
            if mach.tcp:
                problems.add(where, "TOOL CALL with FUNCTION TCPM on")
            m = re.fullmatch(r"TOOL CALL (\d+) Z(?: S(\S+))?", body)
            if not m:
                problems.add(where, "TOOL CALL not of the form 'TOOL CALL n Z S..'")
                continue
            if int(m.group(1)) <= 0:
                problems.add(where, "TOOL CALL %s: tool 0 empties the spindle" % m.group(1))
            if m.group(2) is not None:
                unsigned(m.group(2), where, problems, "spindle speed")
            mach.tool = int(m.group(1))
            mach.up_first = where
            mach.spindle = False
            mach.feed = None
            mach.pos = [None, None, None]
            continue
        kind, m = two_block_cycle(i, body, blocks, where, problems)
        if kind == 32 and m and m.group(1) is not None:
            t = unsigned(m.group(1), where, problems, "tolerance")
            if t is not None and t <= 0:
                problems.add(where, "tolerance T%s is not positive" % m.group(1))
        elif kind == 9 and m:
            # Cycle 9 waits where the tool is, from its definition on.
            t = unsigned(m.group(1), where, problems, "dwell time")
            if t is not None and t <= 0:
                problems.add(where, "dwell time %s is not positive" % m.group(1))
            elif t is not None:
                mach.motions.append({"kind": "dwell", "to": tuple(mach.pos), "time": t, "where": where})
        if kind is not None:
            continue
        if body.startswith("CYCL DEF 200"):
            check_cycle_200(body, cont, where, mach, problems)
            continue
        if body.startswith("CYCL DEF 247"):
            # The datum of a clamping (a program that re-clamps the
            # workpiece): a line of the preset table. Where the axes are
            # after it is not where they were.
            if body != "CYCL DEF 247 DATUM SETTING ~" or len(cont) != 1 or \
                    not re.fullmatch(r"Q339=\+[1-9][0-9]* ;DATUM NUMBER", cont[0]):
                problems.add(where, "cycle 247 not written as 'CYCL DEF 247 DATUM SETTING ~' and "
                                    "'Q339=+n ;DATUM NUMBER' (n >= 1)")
            mach.pos = [None, None, None]
            mach.up_first = where
            continue
        if words[0] == "L":
            ms = check_l(words[1:], where, mach, problems, i == last - 1)
            if 2 in ms or 30 in ms:
                ended = True
            continue
        if words[0] == "CC":
            m = re.fullmatch(r"CC X(\S+) Y(\S+)", body)
            if not m:
                problems.add(where, "CC not of the form 'CC X.. Y..'")
                continue
            x, y = (signed(v, where, problems, "pole coordinate") for v in m.groups())
            if x is not None and y is not None:
                mach.cc = (x, y)
            continue
        if words[0] == "C":
            m = re.fullmatch(r"C(?: X(\S+))?(?: Y(\S+))? DR([+-])(?: F(\S+))?", body)
            if not m or (m.group(1) is None and m.group(2) is None):
                problems.add(where, "C not of the form 'C X.. Y.. DR+/- [F..]'")
                continue
            x = signed(m.group(1), where, problems, "coordinate X") if m.group(1) else None
            y = signed(m.group(2), where, problems, "coordinate Y") if m.group(2) else None
            feed = unsigned(m.group(4), where, problems, "feed") if m.group(4) else None
            mach.arc(where, (x, y), m.group(3) == "+", feed)
            continue
        if words[0] == "CP":
            m = re.fullmatch(r"CP IPA(\S+)(?: IZ(\S+))? DR([+-])?(?: F(\S+))?", body) if " DR" in body else None
            if not m:
                problems.add(where, "CP not of the form 'CP IPA.. [IZ..] DR+/- [F..]' (IPA and DR are needed)")
                continue
            ipa = signed(m.group(1), where, problems, "IPA")
            iz = signed(m.group(2), where, problems, "IZ") if m.group(2) else 0.0
            feed = unsigned(m.group(4), where, problems, "feed") if m.group(4) else None
            if ipa is None or iz is None:
                continue
            ccw = m.group(3) == "+"
            if ipa == 0 or (ipa > 0) != ccw:
                problems.add(where, "IPA%s and DR%s do not turn the same way" % (m.group(1), m.group(3)))
            mach.polar_arc(where, ipa, iz, ccw, feed)
            continue
        problems.add(where, "unknown block '%s'" % body)
    if mach.tcp:
        problems.add("block %d" % blocks[-1][0], "the program ends with FUNCTION TCPM on")
    if mach.plane is not None:
        problems.add("block %d" % blocks[-1][0], "the program ends with the working plane tilted (PLANE RESET missing)")
    if len(blocks) >= 2 and end:
        before = blocks[-2][1].split()
        if not (before and before[0] == "L" and ("M30" in before or "M2" in before)):
            problems.add("block %d" % blocks[-2][0], "the block before END PGM is not the program end (M30 or M2)")
    return problems, mach


# Cycles defined in two blocks: the number, the first block, the second
# block's pattern and how problems name it.
TWO_BLOCK_CYCLES = [
    (32, "CYCL DEF 32.0 TOLERANCE", r"CYCL DEF 32\.1(?: T(\S+))?", "CYCL DEF 32.1", "CYCL DEF 32.1"),
    (9, "CYCL DEF 9.0 DWELL TIME", r"CYCL DEF 9\.1 DWELL (\S+)", "CYCL DEF 9.1 DWELL", "CYCL DEF 9.1"),
]


def two_block_cycle(i, body, blocks, where, problems):
    """(number, match of the second block or None) when block i is either
    block of a two-block cycle, each checked to stand by the other; (None,
    None) otherwise."""
    for number, first, second, second_name, second_short in TWO_BLOCK_CYCLES:
        if body == first:
            nxt = blocks[i + 1][1] if i + 1 < len(blocks) else ""
            if not re.fullmatch(second, nxt):
                problems.add(where, "%s not followed by %s" % (" ".join(first.split()[:3]), second_name))
            return number, None
        m = re.fullmatch(second, body)
        if m:
            if i == 0 or blocks[i - 1][1] != first:
                problems.add(where, "%s not right after %s" % (second_short, first))
            return number, m
    return None, None


def check_cycle_200(body, cont, where, mach, problems):
    if body != "CYCL DEF 200 DRILLING ~":
        problems.add(where, "cycle 200 not written as 'CYCL DEF 200 DRILLING ~'")
    q = {}
    order = []
    for k, line in enumerate(cont):
        last = k == len(cont) - 1
        m = re.fullmatch(r"Q(\d+)=(\S+) ;([^~;]*?)( ~)?", line)
        if not m:
            problems.add(where, "cycle parameter line '%s' not of the form 'Qnnn=value ;TEXT ~'" % line)
            continue
        if bool(m.group(4)) == last:
            problems.add(where, "cycle parameter Q%s: '~' must end every line but the last" % m.group(1))
        n = int(m.group(1))
        v = signed(m.group(2), where, problems, "Q%d" % n)
        if v is not None:
            q[n] = v
        order.append(n)
    if order != CYCLE_200_Q:
        problems.add(where, "cycle 200 parameters %s where %s were expected" %
                     (" ".join("Q%d" % n for n in order), " ".join("Q%d" % n for n in CYCLE_200_Q)))
        return
    if len(q) != len(CYCLE_200_Q):
        return
    if not q[200] > 0:
        problems.add(where, "Q200 (set-up clearance) is not positive")
    if not q[201] < 0:
        problems.add(where, "Q201 (depth) is not negative: the cycle would not drill")
    if not q[202] > 0:
        problems.add(where, "Q202 (plunging depth) is not positive")
    if not q[206] > 0:
        problems.add(where, "Q206 (feed) is not positive")
    if q[204] < q[200]:
        problems.add(where, "Q204 (2nd set-up clearance) is below Q200: the cycle ends at Q200 instead")
    mach.cycle = q


# --- Comparison with the toolpath IR ---------------------------------------------------

def ir_moves(path):
    out = toolpath_ir.read_moves(path)
    for mv in out:
        mv["where"] = "IR line %d" % mv["line"]
    return out


def normalise(moves, decimals):
    """Leaves out moves that go no farther than a unit of the last decimal
    (save near-whole circles),
    merges runs of rapids into their end and runs of flat arcs about one
    centre into one arc."""
    out = []
    for mv in moves:
        start = mv.get("start")
        if start is not None and None not in mv["to"] and mv["kind"] != "dwell":
            near = math.dist(start, mv["to"]) <= 1.5 * 10.0 ** -decimals
            if near and not (mv["kind"] == "arc" and mv["sweep"] > math.pi):
                continue
        if out and joinable(out[-1], mv):
            # Arcs about one centre in a row are one arc (a backend may
            # split an arc, e.g. a near-whole circle into halves).
            out[-1] = joined(out[-1], mv)
            continue
        if mv["kind"] == "rapid" and out and out[-1]["kind"] == "rapid":
            merged = dict(out[-1])
            merged["to"] = tuple(b if b is not None else a for a, b in zip(out[-1]["to"], mv["to"]))
            merged["where"] = mv["where"]
            out[-1] = merged
            continue
        out.append(mv)
    return out


def joinable(prev, mv):
    """Whether mv continues the flat arc prev about the same centre (within
    2 PATH_TOL: printing moves a centre) at the same feed."""
    return (mv["kind"] == "arc" and prev["kind"] == "arc" and prev["ccw"] == mv["ccw"]
            and prev.get("feed") == mv.get("feed") and prev["start"] is not None and mv.get("start") is not None
            and prev["start"][2] == prev["to"][2] == mv["to"][2]
            and math.dist(prev["centre"], mv["centre"]) <= 2 * PATH_TOL)


def joined(prev, mv):
    """The arcs prev and mv as one."""
    merged = dict(prev)
    merged["to"], merged["sweep"], merged["where"] = mv["to"], prev["sweep"] + mv["sweep"], mv["where"]
    merged["pieces"] = arc_pieces(prev) + arc_pieces(mv)
    merged["parts"] = prev.get("parts", [prev]) + mv.get("parts", [mv])
    return merged


def program_moves(motions):
    out = []
    pos = (None, None, None)
    for mv in motions:
        mv = dict(mv)
        mv["start"] = pos if None not in pos else None
        if None in mv["to"]:
            mv["start"] = None
        out.append(mv)
        pos = mv["to"]
    return out


def arc_pieces(mv):
    """An arc as the arcs it was merged from: (start, centre, ccw, sweep)."""
    return mv.get("pieces") or [(mv["start"], mv["centre"], mv["ccw"], mv["sweep"])]


def piece_point(piece, t):
    """The point (x, y) a fraction t along one arc, at its start radius."""
    (sx, sy, _), (cx, cy), ccw, sweep = piece
    a = math.atan2(sy - cy, sx - cx) + (1 if ccw else -1) * t * sweep
    r = math.hypot(sx - cx, sy - cy)
    return (cx + r * math.cos(a), cy + r * math.sin(a))


def chord_deviation(mv):
    """How far an arc strays from its chord (a whole turn: its diameter)."""
    r = math.hypot(mv["start"][0] - mv["centre"][0], mv["start"][1] - mv["centre"][1])
    return r * (1 - math.cos(min(mv["sweep"], math.pi) / 2))


def tiny(mv, decimals):
    """A move too short to compare: a line or an arc (not a near-whole
    circle) whose ends are within three units of the last decimal."""
    start = mv.get("start")
    if start is None or None in start or mv["kind"] in ("rapid", "dwell"):
        return False
    if mv["kind"] == "arc" and mv["sweep"] > math.pi:
        return False
    return math.dist(start, mv["to"]) <= 3 * 10.0 ** -decimals


def compare(prog, ir, problems, decimals):
    """Move by move: the same kind (an arc within PATH_TOL of its chord may be
    a line), the same end, the same feed; arcs also the same direction and
    sweep, and the path (points at eighths of each written arc) within
    PATH_TOL of the IR's circle. A move too short to compare on one side
    may be missing on the other (rounding decides which side has it). The
    sweep is compared coarsely (0.5 rad): ends and path are checked to the
    micron, the sweep catches a turn too many or too few."""
    i = j = 0
    while i < len(prog) and j < len(ir):
        a, b = prog[i], ir[j]
        where = "%s (%s)" % (a["where"], b["where"])
        kind_a, kind_b = a["kind"], b["kind"]
        if kind_a == "linear" and kind_b == "arc" and b.get("turns", 0) == 0 and chord_deviation(b) <= PATH_TOL:
            kind_b = "linear"
        ends = all(a["to"][k] is None or abs(a["to"][k] - b["to"][k]) <= END_TOL for k in range(3))
        turns = kind_a != "arc" or kind_b != "arc" or abs(a["sweep"] - b["sweep"]) <= 0.5
        if kind_a != kind_b or not ends or not turns:
            # Arcs in a row about centres close enough to be one arc on one
            # side but not on the other (printing moves a centre): the side
            # whose arc ends later goes back to its arcs, or the side whose
            # arc ends first takes in its next arc.
            if kind_a == kind_b == "arc" and not ends:
                longer, k = (prog, i) if a["sweep"] > b["sweep"] else (ir, j)
                shorter, q = (ir, j) if longer is prog else (prog, i)
                if "parts" in longer[k]:
                    longer[k:k + 1] = longer[k]["parts"]
                    continue
                if q + 1 < len(shorter) and joinable(shorter[q], shorter[q + 1]):
                    merged = joined(shorter[q], shorter[q + 1])
                    del merged["parts"]  # not to be taken apart again: each step shortens a list
                    shorter[q:q + 2] = [merged]
                    continue
            if tiny(a, decimals):
                i += 1
                continue
            if tiny(b, decimals):
                j += 1
                continue
            if kind_a != kind_b:
                problems.add(where, "the program makes a %s where the IR has a %s" % (a["kind"], b["kind"]))
            elif not turns:
                problems.add(where, "the arc sweeps %.4f deg where the IR sweeps %.4f deg"
                             % (math.degrees(a["sweep"]), math.degrees(b["sweep"])))
            else:
                problems.add(where, "%s ends at %s where the IR ends at %s" % (a["kind"], fmt(a["to"]), fmt(b["to"])))
            return
        i += 1
        j += 1
        if kind_a == "dwell":
            if abs(a["time"] - b["time"]) > 0.0006:
                problems.add(where, "a dwell of %g s where the IR has %g s" % (a["time"], b["time"]))
            continue
        if kind_a != "rapid" and abs((a.get("feed") or 0) - b.get("feed", 0)) > FEED_TOL:
            problems.add(where, "feed %s where the IR has %s" % (a.get("feed"), b.get("feed")))
        if kind_a == "arc":
            if a["start"] is None:
                problems.add(where, "arc from an unknown position")
                continue
            centre = b["centre"]
            radius = math.hypot(b["start"][0] - centre[0], b["start"][1] - centre[1])
            if a["ccw"] != b["ccw"]:
                problems.add(where, "the arc turns the other way")
            for piece in arc_pieces(a):
                off = max(abs(math.dist(piece_point(piece, t / 8), centre) - radius) for t in range(1, 8))
                if off > PATH_TOL:
                    problems.add(where, "the arc strays %.4f mm from the IR's circle about %s, radius %.4f"
                                 % (off, fmt(centre), radius))
                    break
    rest = [mv for mv in prog[i:] if not tiny(mv, decimals)] + [mv for mv in ir[j:] if not tiny(mv, decimals)]
    if rest:
        problems.add(rest[0]["where"], "the program makes %d moves and the IR has %d: the rest do not pair up"
                     % (len(prog), len(ir)))


def fmt(v):
    return "(" + ", ".join("?" if x is None else "%.4f" % x for x in v) + ")"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("program", help="the Klartext program (.h)")
    ap.add_argument("--ir", help="the toolpath IR it was written from: compare the moves")
    ap.add_argument("--arc-tol", type=float, default=0.001,
                    help="most a C arc's start and end radius may differ, mm (default 0.001)")
    ap.add_argument("--decimals", type=int, default=3, help="coordinate decimals of the program (default 3)")
    args = ap.parse_args()
    with open(args.program, encoding="ascii", errors="replace") as f:
        text = f.read()
    problems, mach = check_program(text, args.arc_tol)
    if args.ir:
        # Moves that tilt the tool (under FUNCTION TCPM) are check-tcp.py's.
        made = [mv for mv in program_moves(mach.motions) if not mv.get("tcp")]
        planned = [mv for mv in ir_moves(args.ir) if mv.get("axis", (0.0, 0.0, 1.0)) == (0.0, 0.0, 1.0)]
        compare(normalise(made, args.decimals), normalise(planned, args.decimals), problems, args.decimals)
    if problems.items:
        for item in problems.items:
            print("%s: %s" % (args.program, item))
        print("%s: %d problem(s)" % (args.program, len(problems.items)))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
