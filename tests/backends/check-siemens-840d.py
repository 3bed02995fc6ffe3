#!/usr/bin/env python3
"""Checks SINUMERIK 840D main programs written by stepnc.

No Sinumerik interpreter is packaged for Debian, so this script reads
a program as the manuals in docs/backends.md ("Sources") describe the controller
and reports what would be wrong there:

  * the frame: `%_N_NAME_MPF` first (NAME: letters, digits, underscores,
    upper case, two letters first, at most 24 characters), `;$PATH=/_N_MPF_DIR`
    second, M30 last;
  * every block's words: G and M codes from short lists of the ones stepnc
    may write, address letters X Y Z I J K F S T D with well-formed numbers
    (decimal point on lengths and feeds, no exponent, no -0), `CR=`, `TURN=`,
    `MSG("...")`, `MCALL`, `CYCLE81/82/83/84(...)` with their argument counts, `G4 F` (a
    dwell, seconds) in a block of its own
    and the documented signs (RTP/RFP/DP absolute, SDIS/DPR unsigned), and
    `CYCLE832(tol, mode, 1)`;
  * block numbers, when there are any, strictly increasing; lines no longer
    than the limit;
  * the modal state a move needs: G90 G71 G17 set, a tool changed in with
    its D offset (`T5 D1` then `M6`, or `T5`, `M6`, `D1`), the spindle on and
    a feed for feed moves;
  * arcs, from the position tracked through the printed numbers: with I/J the
    radius at the start and at the end agree within 0.001 mm (whole circles
    too); with CR= the radius reaches across the chord; TURN= only with I/J;
  * deposition programs (with --machine, or --option=--machine=..., naming
    a machine whose [deposition] table is written for siemens-840d,
    docs/additive.md): a block that is one of the table's codes (its value
    a number) is the machine's word, accepted; feed moves then need no
    spindle, and no rapid may run while the energy is on;
  * the first move of the program, and the first after each tool change,
    is Z alone (up to the clearance height): where the tool is then is the
    machine's business, so X and Y only move once it is up (not in a lathe
    program, whose tool comes from its turret outside the stock);
  * lathe programs (docs/turning.md): G18 (the ZX plane: arcs in Z and X,
    G3 counter-clockwise seen from +Y), DIAMON (X a diameter), G95 (F per
    revolution), G96 with S and LIMS= (constant cutting speed and its
    spindle limit), G97; Y is not written;
  * modal cycles: `MCALL CYCLE..` then position blocks (X/Y only, from above
    the reference plane) then a bare `MCALL`, nothing else in between;
  * cubic splines: `CSPLINE BAUTO EAUTO` (no end condition taken from the
    blocks around) then points with X and Y only, in the plane at one
    height; each point is a move whose end must be the plan's (the curve
    between is the controller's cubic spline through the points).

With --ir (one program) the moves the program makes are also compared with
the toolpath IR's, within the rounding of 3 decimals: feed moves one by one
(an arc may be written in several pieces, a CR= arc's centre may move with
its rounded end points), runs of rapids by where they end. A drilling cycle
makes the moves its documented parameters describe (CYCLE82: CYCLE81's and
a dwell of DTB seconds at the bottom; CYCLE83: strokes as long as the first,
no degression; CYCLE84: feed pitch times SST in, times SST1
out); its rapids are the controller's, so in a program with cycles only the
feed moves are compared.

With --stepnc, each argument is an input (STEP-NC or IR text) that the script
first compiles with that stepnc (extra options after --option), into a
program and its toolpath IR, and checks both ways.

Exit 0 when every program is clean (one `ok:` line each), 1 listing each
problem as `FILE:LINE: problem`.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib

import toolpath_ir
from toolpath_ir import arc_sweep

RADIUS_TOL = 1e-3
MAX_NAME = 24

# G54..G57 and the user frames G505..G599: the work offset of each clamping
# of a program that re-clamps the workpiece (docs/setups.md).
G_CODES = {0, 1, 2, 3, 4, 17, 40, 64, 71, 90, 94, 642} | set(range(54, 58)) | set(range(505, 600))
# Lathe programs (docs/turning.md): the ZX plane, feed per revolution,
# constant cutting speed and its end.
G_CODES |= {18, 33, 95, 96, 97}
# G33: a thread, the feed K per spindle revolution along the path.
MOTION = {0, 1, 2, 3, 33}
M_CODES = {0, 1, 3, 4, 5, 6, 7, 8, 9, 30}
LENGTH_WORDS = set("XYZIJK") | {"CR", "F"}
INTEGER_WORDS = {"S", "T", "D", "TURN", "LIMS"}
# Cycle: (fewest arguments, most arguments or None).
CYCLES = {"CYCLE81": (5, 5), "CYCLE82": (6, 6), "CYCLE83": (12, None), "CYCLE84": (12, None)}

NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
TOKEN_RE = re.compile(
    r'\s*(?:(?P<msg>MSG\("[^"]*"\))'
    r"|(?P<call>(?:CYCLE\d+)\([^()]*\))"
    r"|(?P<mcall>MCALL)(?![A-Z0-9_])"
    r"|(?P<keyword>CSPLINE|BAUTO|EAUTO|DIAMON|TRAORI|TRAFOOF|SUPA)(?![A-Z0-9_])"
    r"|(?P<assign>(?:CR|TURN|LIMS)=(?P<avalue>" + NUMBER + r"))"
    r"|(?P<letter>[A-Z])(?P<value>" + NUMBER + r"))")


def split_comment(line):
    """The block's code and its comment (after a ';' outside quotes)."""
    quoted = False
    for i, c in enumerate(line):
        if c == '"':
            quoted = not quoted
        elif c == ";" and not quoted:
            return line[:i], line[i + 1:]
    return line, None


def number_problem(address, text):
    if re.search(r"[eE]", text):
        return "%s%s: exponent notation" % (address, text)
    if re.fullmatch(r"-0*\.?0*", text):
        return "%s%s: negative zero" % (address, text)
    if address in LENGTH_WORDS and "." not in text:
        return "%s%s: no decimal point (an integer may be read otherwise)" % (address, text)
    if address in INTEGER_WORDS and not re.fullmatch(r"\d+", text):
        return "%s%s: not a whole number" % (address, text)
    return None


def cycle_args(call):
    name, inside = call.split("(", 1)
    return name, [a.strip() for a in inside[:-1].split(",")]


def arg_number(text):
    if text == "":
        return None
    if not re.fullmatch(NUMBER, text) or re.search(r"[eE]", text):
        raise ValueError(text)
    return float(text)


# How far (along the arc, mm) the program's sweep may differ from the plan's:
# the printed centre may sit up to a unit of the last decimal off the plan's
# (it is chosen so that start and end radius agree), which turns the angle a
# little; a wrong direction or a missing turn is far beyond this.
ARC_LENGTH_TOL = 0.01


def planned_moves(path):
    """The moves of every `moves` block of a toolpath IR file, in order."""
    return toolpath_ir.read_moves(path)


def on_circle(piece, centre, radius, tol):
    """Whether an arc of the program lies on the planned circle: about the plan's centre, or through
    points on the circle at both ends and in the middle. The centre a controller reads moves with the
    rounding of the end points, far on a short arc: a CR= arc's always, an I/J arc's where stepnc
    balances it between the printed ends (a 0.2 mm arc moves it by microns off the path's)."""
    if math.dist(piece["centre"], centre) <= tol:
        return True
    a = math.atan2(piece["start"][1] - piece["centre"][1], piece["start"][0] - piece["centre"][0])
    a += (1 if piece["ccw"] else -1) * piece["sweep"] / 2
    middle = (piece["centre"][0] + piece["radius"] * math.cos(a), piece["centre"][1] + piece["radius"] * math.sin(a))
    return all(abs(math.dist(p, centre) - radius) <= tol for p in (piece["start"][:2], middle, piece["to"][:2]))


def arc_text(m):
    return "about (%.4f, %.4f) %s" % (m["centre"][0], m["centre"][1], "ccw" if m["ccw"] else "cw")


def compare_moves(planned, made, feeds_only, decimals=3):
    """Differences between the planned moves and the program's: feed moves one by one (an arc may be
    written in pieces), runs of rapids by where they end; moves no longer than the rounding are left out.
    With feeds_only (canned cycles, whose own rapids are the controller's) rapids are not compared."""
    # Each axis is rounded by up to half a unit of the last decimal: a point
    # moves by up to 0.87 units; a little room above that.
    tol = 1.2 * 10 ** -decimals

    def squeeze(moves):
        out, last = [], None
        for m in moves:
            if m["kind"] == "dwell":
                out.append(m)
                continue
            if None in m["to"]:
                continue
            # No motion as printed: a move that goes nowhere in the plan may
            # print one unit long where its ends round either side of a
            # half unit (a connector a fraction of a micrometre long).
            if m["kind"] != "arc" and last is not None and math.dist(m["to"], last) <= tol:
                continue
            last = m["to"]
            if m["kind"] == "rapid" and out and out[-1]["kind"] == "rapid":
                out[-1] = m  # a run of rapids: where it ends
            else:
                out.append(m)
        return [m for m in out if not (feeds_only and m["kind"] == "rapid")]

    want, got = squeeze(planned), squeeze(made)
    problems = []
    j = 0
    for w in want:
        if j >= len(got):
            problems.append("IR line %d: %s to %s: the program has no more moves" % (w["line"], w["kind"], w["to"]))
            break
        g = got[j]
        where = "IR line %d, program line %d" % (w["line"], g["line"])
        if g["kind"] != w["kind"]:
            problems.append("%s: the plan has a %s, the program a %s" % (where, w["kind"], g["kind"]))
            break
        if w["kind"] == "dwell":
            if abs(g["time"] - w["time"]) > 0.0006:
                problems.append("%s: a dwell of %g s, the plan's %g s" % (where, g["time"], w["time"]))
                break
            j += 1
            continue
        if w["kind"] == "arc":
            # Pieces about the same centre, the same way, until the sweep is made.
            sweep, end = 0.0, None
            while j < len(got) and got[j]["kind"] == "arc" and got[j]["ccw"] == w["ccw"] and \
                    on_circle(got[j], w["centre"], w["radius"], 2 * tol):
                sweep += got[j]["sweep"]
                end = got[j]
                j += 1
                if abs(sweep - w["sweep"]) * w["radius"] <= ARC_LENGTH_TOL or sweep > w["sweep"]:
                    break
            if end is None:
                problems.append("%s: the arc turns %s, the plan's %s" % (where, arc_text(g), arc_text(w)))
                break
            if abs(sweep - w["sweep"]) * w["radius"] > ARC_LENGTH_TOL:
                problems.append("%s: the arc sweeps %.4f rad, the plan %.4f rad" % (where, sweep, w["sweep"]))
            g = end
        else:
            j += 1
        if math.dist(g["to"], w["to"]) > tol:
            problems.append("%s: %s ends at %s, the plan at %s" % (where, w["kind"], g["to"], w["to"]))
            break
        if w["kind"] != "rapid" and abs(g["feed"] - w["feed"]) > 0.051:
            problems.append("%s: feed %g, the plan's %g" % (where, g["feed"], w["feed"]))
    if not problems and j < len(got):
        problems.append("program line %d: a %s the plan does not have" % (got[j]["line"], got[j]["kind"]))
    return problems, len(want)


REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def deposition_codes(spec):
    """The [deposition] codes of machine `spec` (a file or a shipped name) as
    (key, regex) pairs; [] when it has none. A code written for another
    target is an error of the caller's (returned as a string)."""
    if not spec:
        return []
    path = spec if os.path.exists(spec) else os.path.join(REPO, "machines", spec + ".toml")
    with open(path, "rb") as f:
        table = tomllib.load(f).get("deposition")
    if not table:
        return []
    if table.get("target") != "siemens-840d":
        return "the machine's deposition codes are for %s" % table.get("target")
    codes = []
    for key in ("energy_on", "energy_off", "power", "powder", "wire"):
        code = table.get(key)
        if code:
            pattern = re.escape(code)
            for placeholder in ("power", "powder", "wire"):
                pattern = pattern.replace(re.escape("{%s}" % placeholder), r"-?\d+(\.\d+)?")
            codes.append((key, re.compile(pattern + "$")))
    return codes


class Checker:
    def __init__(self, name, lines, max_line, codes=()):
        self.name = name
        self.codes = codes
        self.energy = False
        self.deposits = False
        self.lines = lines
        self.max_line = max_line
        self.problems = []
        self.pos = {"X": None, "Y": None, "Z": None}
        self.modal = {"absolute": False, "metric": False, "plane": False}
        # A lathe program: G18 (the ZX plane), X a diameter under DIAMON,
        # F per revolution under G95, S a cutting speed under G96 (with
        # LIMS= its spindle limit).
        self.plane = "xy"
        self.lathe = False
        self.diameter = False
        self.traori = False  # the 840D's TRAORI on
        # 3+2 (CYCLE800): the swivel in force ((angles about Z, Y, X in
        # turn), the rotated zero) or None, the face the last re-clamp
        # message put up, the Z of the last G0 SUPA Z.. with nothing moved
        # since, and what each swivel turned with.
        self.swivel = None
        self.reclamp = None
        self.up = None
        self.turns = []
        self.per_rev = False
        self.css = False
        self.motion = None
        self.feed = None
        self.spindle_speed = 0
        self.spindle_on = False
        self.tool_selected = None
        self.tool_in_spindle = None
        self.offset = None
        self.pending_offset = None
        self.mcall = None
        self.ended_at = None
        self.last_number = None
        self.counts = {"blocks": 0, "moves": 0, "ijk": 0, "cr": 0, "turn": 0, "holes": 0}
        # What the program makes, for --ir: dicts with kind (rapid, linear,
        # arc), to, feed, and for arcs centre, ccw, sweep (radians, turns
        # included), radius; `line` is where it was written.
        self.made = []
        self.lacking = set()
        # Where the first move is due to go up along Z alone: the program's
        # start, or the line of the tool change (M6).
        self.up_first = "the program start"

    def problem(self, n, text):
        self.problems.append("%s:%d: %s" % (self.name, n, text))

    # --- the frame -------------------------------------------------------------------

    def check_frame(self):
        if not self.lines:
            self.problem(1, "empty program")
            return
        m = re.fullmatch(r"%_N_(\w+)_MPF", self.lines[0])
        if not m:
            self.problem(1, "first line is not %%_N_NAME_MPF: %r" % self.lines[0])
        else:
            name = m.group(1)
            if not re.fullmatch(r"[A-Z]{2}[A-Z0-9_]*", name):
                self.problem(1, "program name %s: letters, digits and underscores, upper case, two letters first"
                             % name)
            if len(name) > MAX_NAME:
                self.problem(1, "program name %s is longer than %d characters" % (name, MAX_NAME))
        if len(self.lines) < 2 or self.lines[1] != ";$PATH=/_N_MPF_DIR":
            self.problem(2, "second line is not ;$PATH=/_N_MPF_DIR")

    # --- blocks ---------------------------------------------------------------------

    def run(self):
        self.check_frame()
        for n, line in enumerate(self.lines, 1):
            if self.max_line and len(line) > self.max_line:
                self.problem(n, "line of %d characters, over the limit of %d" % (len(line), self.max_line))
            if n == 1:
                continue
            code, _ = split_comment(line)
            code = code.strip()
            m = re.match(r"N(\d+)(?:\s+|$)", code)
            if m:
                number = int(m.group(1))
                if self.last_number is not None and number <= self.last_number:
                    self.problem(n, "block number N%d after N%d" % (number, self.last_number))
                if number == 0:
                    self.problem(n, "block number N0")
                self.last_number = number
                code = code[m.end():]
            elif self.last_number is not None and code:
                self.problem(n, "block without a number among numbered blocks")
            if not code:
                continue
            if self.ended_at is not None:
                self.problem(n, "block after M30 (line %d)" % self.ended_at)
            self.counts["blocks"] += 1
            machine = next((key for key, pattern in self.codes if pattern.match(code)), None)
            if machine:
                self.deposits = True
                if machine in ("energy_on", "energy_off"):
                    self.energy = machine == "energy_on"
                continue
            words = self.tokenize(n, code)
            if words is not None:
                self.block(n, words)
        if self.ended_at is None:
            self.problem(len(self.lines), "the program does not end with M30")
        if self.mcall is not None:
            self.problem(self.mcall["line"], "MCALL %s never cancelled by a bare MCALL" % self.mcall["cycle"])
        if self.swivel is not None:
            self.problem(len(self.lines), "the program ends with the plane swivelled (CYCLE800 with _TC \"0\" missing)")

    def tokenize(self, n, code):
        words = []
        at = 0
        while at < len(code):
            m = TOKEN_RE.match(code, at)
            if not m or m.end() == at:
                rest = code[at:].strip()
                if rest:
                    self.problem(n, "not a word this target writes: %r" % rest)
                    return None
                break
            at = m.end()
            if m.group("msg"):
                words.append(("MSG", m.group("msg")))
            elif m.group("call"):
                words.append(("CALL", m.group("call")))
            elif m.group("mcall"):
                words.append(("MCALL", ""))
            elif m.group("keyword"):
                words.append((m.group("keyword"), ""))
            elif m.group("assign"):
                words.append((m.group("assign").split("=")[0], m.group("avalue")))
            else:
                words.append((m.group("letter"), m.group("value")))
        return words

    def block(self, n, words):
        seen = {}
        gs, ms = [], []
        bad = False
        # The rotary axes alone at rapid, back to 0 after a swivel is
        # deselected with the tool up (3+2), are the only ones without TRAORI.
        homing = all(a in "ABCG" for a, _ in words) and ("G", "0") in words and self.up is not None and \
            self.swivel is None
        for address, value in words:
            if address in ("MSG", "CALL", "MCALL", "CSPLINE", "BAUTO", "EAUTO", "DIAMON", "TRAORI", "TRAFOOF", "SUPA"):
                continue
            if address in "ABC" and not self.traori and not homing:
                self.problem(n, "rotary axis %s with the transformation off (TRAORI first)" % address)
                bad = True
            elif address in LENGTH_WORDS or address in INTEGER_WORDS or address in "GM" or address in "ABC":
                problem = number_problem(address, value)
                if problem:
                    self.problem(n, problem)
                    bad = True
            else:
                self.problem(n, "address %s is not one this target writes" % address)
                bad = True
        if bad:
            return
        for address, value in words:
            if address in ("TRAORI", "TRAFOOF"):
                # The 840D's 5-axis transformation (PROCESSES.md C2): alone in
                # its block, on then off; X Y Z stay the tool tip, A B C are
                # the rotary axes (check-tcp.py checks those moves).
                if len(words) != 1:
                    self.problem(n, "%s shares its block" % address)
                if (address == "TRAORI") == self.traori:
                    self.problem(n, "%s while the transformation is %s" % (address, "on" if self.traori else "off"))
                if self.swivel is not None:
                    self.problem(n, "%s with the plane swivelled (CYCLE800)" % address)
                self.traori = address == "TRAORI"
                return
            if address in ("MSG", "CALL", "MCALL", "CSPLINE", "BAUTO", "EAUTO", "SUPA") or address in "ABC":
                continue
            if address == "DIAMON":
                self.diameter = True
                continue
            if address == "G":
                g = float(value)
                if g != int(g) or int(g) not in G_CODES:
                    self.problem(n, "G%s is not a G code this target writes" % value)
                    return
                gs.append(int(g))
            elif address == "M":
                m = float(value)
                if m != int(m) or int(m) not in M_CODES:
                    self.problem(n, "M%s is not an M code this target writes" % value)
                    return
                ms.append(int(m))
            else:
                if address in seen:
                    self.problem(n, "%s written twice in one block" % address)
                    return
                seen[address] = float(value)
        if 4 in gs:
            # G4 F: a dwell of F seconds, in a block of its own; F is a time
            # there, not the feed (which stays as it was).
            if len(words) != 2 or "F" not in seen:
                self.problem(n, "G4 takes F (seconds) in a block of its own")
            elif seen["F"] <= 0:
                self.problem(n, "a dwell of G4 F%s" % seen["F"])
            else:
                self.made.append(dict(kind="dwell", to=(self.pos["X"], self.pos["Y"], self.pos["Z"]),
                                      time=seen["F"], feed=0, line=n))
            return
        if len([g for g in gs if g in MOTION]) > 1:
            self.problem(n, "two motion G codes in one block")
        kinds = [a for a, _ in words]
        if "MSG" in kinds and len(words) > 1:
            self.problem(n, "MSG shares its block")
        for address, value in words:
            m = re.search(r"re-clamp the workpiece with its ([+-][XYZ]) face up", value) if address == "MSG" else None
            if m:
                self.reclamp = m.group(1)
        if "SUPA" in kinds:
            # Up with every frame suppressed (machine coordinates) before a
            # swivel: no move of the program's, where the tool is after it
            # is not known.
            if gs != [0] or list(seen) != ["Z"]:
                self.problem(n, "SUPA other than G0 SUPA Z.. (the tool up before the plane swivels)")
            self.pos = {"X": None, "Y": None, "Z": None}
            self.up = seen.get("Z")
            return
        if homing and any(a in "ABC" for a in kinds):
            self.pos = {"X": None, "Y": None, "Z": None}
            return

        # MCALL: on with a cycle, off bare.
        if "MCALL" in kinds:
            self.mcall_block(n, words)
            return
        calls = [v for a, v in words if a == "CALL"]
        for call in calls:
            self.direct_call(n, call, len(words))

        keywords = [a for a in kinds if a in ("CSPLINE", "BAUTO", "EAUTO")]
        if keywords and keywords != ["CSPLINE", "BAUTO", "EAUTO"]:
            self.problem(n, "a spline starts with CSPLINE BAUTO EAUTO, found %s" % " ".join(keywords))
        if keywords and gs and any(g in MOTION for g in gs):
            self.problem(n, "CSPLINE and a motion G code in one block")
        if keywords:
            self.motion = "cspline"
        for g in gs:
            if g in MOTION:
                self.motion = g
            elif g == 90:
                self.modal["absolute"] = True
            elif g == 71:
                self.modal["metric"] = True
            elif g == 17:
                self.modal["plane"] = True
                self.plane = "xy"
            elif g == 18:
                self.modal["plane"] = True
                self.plane = "zx"
                self.lathe = True
            elif g in (94, 95):
                self.per_rev = g == 95
            elif g == 96:
                if "S" not in seen or seen["S"] <= 0:
                    self.problem(n, "G96 without a cutting speed S")
                if "LIMS" not in seen or seen["LIMS"] <= 0:
                    self.problem(n, "G96 without LIMS= (the spindle would race as the tool nears the axis)")
                self.css = True
                # G96 turns G95 on (the manual's words)
                self.per_rev = True
            elif g == 97:
                self.css = False
        if "F" in seen:
            if seen["F"] <= 0:
                self.problem(n, "feed F%s" % seen["F"])
            self.feed = seen["F"]
        if "S" in seen:
            self.spindle_speed = seen["S"]
        if "T" in seen:
            self.tool_selected = int(seen["T"])
        for m in ms:
            self.m_code(n, m)
        if "LIMS" in seen and 96 not in gs:
            self.problem(n, "LIMS= outside a G96 block")
        if "D" in seen:
            # D before the M6 that changes in the selected tool is that tool's
            # offset, taken on by the M6; otherwise it applies at once.
            if self.tool_selected is not None and self.tool_selected != self.tool_in_spindle:
                self.pending_offset = int(seen["D"])
            else:
                self.offset = int(seen["D"])
        if any(a in seen for a in "XYZ") or ("I" in seen or "J" in seen or "CR" in seen):
            self.move(n, seen)
        elif "TURN" in seen or "K" in seen:
            self.problem(n, "TURN= or K without a move")

    def m_code(self, n, m):
        if m in (3, 4):
            if self.spindle_speed <= 0:
                self.problem(n, "spindle on (M%d) without a speed S" % m)
            self.spindle_on = True
        elif m == 5:
            self.spindle_on = False
        elif m == 6:
            if self.mcall is not None:
                self.problem(n, "tool change while MCALL %s is active" % self.mcall["cycle"])
            if self.tool_selected is None:
                self.problem(n, "M6 without a tool selected by T")
            self.tool_in_spindle = self.tool_selected
            self.offset = self.pending_offset
            self.pending_offset = None
            # The tool change position is the machine's: the axes are unknown
            # until written again, and the spindle is stopped.
            self.pos = {"X": None, "Y": None, "Z": None}
            self.spindle_on = False
            self.up_first = "the tool change on line %d" % n
        elif m == 30:
            if self.mcall is not None:
                self.problem(n, "M30 while MCALL %s is active" % self.mcall["cycle"])
            self.ended_at = n

    # --- moves ----------------------------------------------------------------------

    def ready_to_move(self, n, feed_move, need_feed=True):
        """Reports what a move lacks, each thing once until it is set again."""
        lacking = []
        if not self.modal["absolute"]:
            lacking.append("a move before G90 (absolute positions)")
        if not self.modal["metric"]:
            lacking.append("a move before G71 (mm)")
        if self.tool_in_spindle is None:
            lacking.append("a move with no tool changed in (T.. M6)")
        elif not self.offset:
            lacking.append("a move without the tool's D offset (its length)")
        if feed_move:
            if need_feed and not self.feed:
                lacking.append("a feed move with no feed F")
            if not self.spindle_on and not self.deposits:
                lacking.append("a feed move with the spindle off")
        elif self.energy:
            self.problem(n, "a rapid with the deposition head's energy on")
        for text in lacking:
            if text not in self.lacking:
                self.problem(n, text)
        self.lacking = set(lacking)

    def move(self, n, seen):
        self.up = None
        if self.motion is None:
            self.problem(n, "axis words with no motion G code (G0 G1 G2 G3)")
            return
        self.counts["moves"] += 1
        if self.up_first and self.lathe:
            # A lathe's tool comes from its turret outside the stock: no Z first.
            self.up_first = None
        if self.up_first:
            if self.motion != 0 or any(a in seen for a in ("X", "Y", "I", "J", "CR", "TURN")):
                self.problem(n, "the first move after %s is not G0 with Z alone (up to the clearance height "
                                "before X and Y move)" % self.up_first)
            self.up_first = None
        if self.mcall is not None:
            self.cycle_position(n, seen)
            return
        self.ready_to_move(n, self.motion != 0)
        if self.motion in (2, 3):
            self.arc(n, seen)
            return
        if self.motion == 33:
            # A thread: K the lead (mm per revolution), at a constant spindle
            # speed (G97: the feed follows the spindle).
            if not self.lathe:
                self.problem(n, "G33 outside a lathe program (G18)")
            if "K" not in seen or seen["K"] <= 0:
                self.problem(n, "G33 without its lead K")
            if self.css:
                self.problem(n, "G33 under G96: a thread needs a constant spindle speed (G97)")
            self.advance(n, seen)
            self.make(n, "linear", seen.get("K", 0))
            return
        if self.motion == "cspline" and any(a not in ("X", "Y", "F") for a in seen):
            self.problem(n, "a spline point with more than X, Y and F")
        for bad in ("I", "J", "K", "CR", "TURN"):
            if bad in seen:
                self.problem(n, "%s on a straight move" % bad)
        self.advance(n, seen)
        self.make(n, "rapid" if self.motion == 0 else "linear", self.feed if self.motion else 0)

    def advance(self, n, seen):
        """The tracked position after a block's axis words: X halved under DIAMON;
        a lathe's Y is 0."""
        for axis in "XYZ":
            if axis in seen:
                self.pos[axis] = seen[axis] / 2 if axis == "X" and self.diameter else seen[axis]
        if self.lathe:
            if "Y" in seen:
                self.problem(n, "Y in a lathe program")
            self.pos["Y"] = 0.0

    def make(self, n, kind, feed, at=None, **arc):
        to = at if at is not None else (self.pos["X"], self.pos["Y"], self.pos["Z"])
        self.made.append(dict(kind=kind, to=to, feed=feed or 0, line=n, tcp=self.traori,
                              frame=("cycle800", self.swivel, self.reclamp), **arc))

    def arc(self, n, seen):
        if not self.modal["plane"]:
            self.problem(n, "an arc before G17 (XY plane)")
        if self.plane == "zx":
            # (Z, X): G3 counter-clockwise seen from +Y; X a radius here.
            x_end = seen["X"] / 2 if "X" in seen and self.diameter else seen.get("X", self.pos["X"])
            start = (self.pos["Z"], self.pos["X"])
            end = (seen.get("Z", self.pos["Z"]), x_end)
            if "J" in seen or "Y" in seen:
                self.problem(n, "J or Y on an arc in the ZX plane")
            offset = (seen.get("K", 0.0), seen.get("I", 0.0))
        else:
            if "K" in seen:
                self.problem(n, "K on an arc in the XY plane")
            start = (self.pos["X"], self.pos["Y"])
            end = (seen.get("X", self.pos["X"]), seen.get("Y", self.pos["Y"]))
            offset = (seen.get("I", 0.0), seen.get("J", 0.0))
        ccw = self.motion == 3
        centre = None
        if None in start or None in end:
            self.problem(n, "an arc from an unknown position")
        elif "CR" in seen:
            self.counts["cr"] += 1
            if "I" in seen or "J" in seen:
                self.problem(n, "an arc with both CR= and I/J")
            if "TURN" in seen:
                self.problem(n, "TURN= with CR= (CR arcs are less than a whole turn)")
            r = abs(seen["CR"])
            chord = math.dist(start, end)
            if chord < 1e-9:
                self.problem(n, "a whole circle with CR= (it needs I/J)")
            elif r == 0 or r < chord / 2 - RADIUS_TOL:
                self.problem(n, "CR=%g is shorter than half the chord (%.4f mm)" % (seen["CR"], chord / 2))
            else:
                # The centre on the side the direction and the sign say: left
                # of the chord for a ccw arc under half a turn.
                h = math.sqrt(max(r * r - chord * chord / 4, 0.0))
                left = (-(end[1] - start[1]) / chord, (end[0] - start[0]) / chord)
                side = (1 if ccw else -1) * (1 if seen["CR"] > 0 else -1)
                centre = ((start[0] + end[0]) / 2 + side * h * left[0], (start[1] + end[1]) / 2 + side * h * left[1])
        elif "I" in seen or "J" in seen or ("K" in seen and self.plane == "zx"):
            self.counts["ijk"] += 1
            if "TURN" in seen:
                self.counts["turn"] += 1
            centre = (start[0] + offset[0], start[1] + offset[1])
            r0, r1 = math.dist(start, centre), math.dist(end, centre)
            if r0 < 1e-9:
                centre = None
            if r0 < 1e-9:
                self.problem(n, "an arc of radius 0")
            elif abs(r0 - r1) > RADIUS_TOL:
                self.problem(n, "arc radius %.4f at the start and %.4f at the end differ by %.4f mm (more than %g)"
                             % (r0, r1, abs(r0 - r1), RADIUS_TOL))
        else:
            self.problem(n, "an arc with neither I/J nor CR=")
        self.advance(n, seen)
        if centre is not None:
            sweep = arc_sweep(start, end, centre, ccw) + 2 * math.pi * seen.get("TURN", 0)
            self.make(n, "arc", self.feed, centre=centre, ccw=ccw, sweep=sweep, radius=math.dist(start, centre),
                      start=start, cr="CR" in seen)

    # --- cycles ---------------------------------------------------------------------

    def cycle_parameters(self, n, call):
        """RTP, RFP, SDIS, DP of a drilling cycle call, after checking its arguments; None when wrong."""
        name, args = cycle_args(call)
        if name == "CYCLE832":
            self.problem(n, "CYCLE832 is not a drilling cycle")
            return None
        if name not in CYCLES:
            self.problem(n, "%s is not a cycle this target writes" % name)
            return None
        low, high = CYCLES[name]
        if len(args) < low or (high is not None and len(args) > high):
            self.problem(n, "%s with %d arguments (it takes %s)" % (
                name, len(args), low if high == low else "%d or more" % low))
            return None
        try:
            values = [arg_number(a) for a in args]
        except ValueError as e:
            self.problem(n, "%s: argument %r is not a plain number" % (name, str(e)))
            return None
        for a in args:
            if re.fullmatch(r"-0*\.?0*", a):
                self.problem(n, "%s: argument %s is a negative zero" % (name, a))
        rtp, rfp, sdis, dp, dpr = values[:5]
        if None in (rtp, rfp, sdis) or (dp is None and dpr is None):
            self.problem(n, "%s without RTP, RFP, SDIS and a depth" % name)
            return None
        if sdis < 0 or (dpr is not None and dpr < 0):
            self.problem(n, "%s: SDIS and DPR are unsigned" % name)
        depth = dp if dp is not None else rfp - dpr
        if depth >= rfp + sdis:
            self.problem(n, "%s: the depth %g is not below the reference plane RFP + SDIS = %g" % (
                name, depth, rfp + sdis))
        if rtp < rfp + sdis:
            self.problem(n, "%s: the retract plane RTP %g is below RFP + SDIS = %g" % (name, rtp, rfp + sdis))
        if name in ("CYCLE81", "CYCLE82", "CYCLE83") and not self.feed:
            self.problem(n, "%s with no feed F set" % name)
        if name == "CYCLE83":
            fdep, fdpr, dam = values[5], values[6], values[7]
            vari = values[11]
            if fdep is None and fdpr is None:
                self.problem(n, "CYCLE83 without a first depth (FDEP or FDPR)")
            elif fdep is not None and not depth <= fdep < rfp + sdis:
                self.problem(n, "CYCLE83: the first depth FDEP %g is not between the depth and RFP + SDIS" % fdep)
            if (fdpr is not None and fdpr < 0) or (dam is not None and dam < 0):
                self.problem(n, "CYCLE83: FDPR and DAM are unsigned")
            if vari not in (0, 1):
                self.problem(n, "CYCLE83: VARI is 0 (chip breaking) or 1 (full retract), not %s" % args[11])
        if name == "CYCLE84":
            sdac, mpit, pit, sst = values[6], values[7], values[8], values[10]
            if sdac not in (3, 4, 5):
                self.problem(n, "CYCLE84: SDAC (the spindle after the cycle) is 3, 4 or 5, not %s" % args[6])
            if not mpit and not pit:
                self.problem(n, "CYCLE84 without a thread pitch (MPIT or PIT)")
            if not sst or sst <= 0:
                self.problem(n, "CYCLE84 without a tapping speed SST")
        return {"cycle": name, "rtp": rtp, "rfp": rfp, "r": rfp + sdis, "depth": depth, "values": values,
                "line": n, "holes": 0}

    def mcall_block(self, n, words):
        if len(words) == 1:
            if self.mcall is None:
                self.problem(n, "bare MCALL with no modal call active")
            elif self.mcall["holes"] == 0:
                self.problem(n, "MCALL %s (line %d) cancelled before any position"
                             % (self.mcall["cycle"], self.mcall["line"]))
            self.mcall = None
            return
        if len(words) != 2 or words[1][0] != "CALL":
            self.problem(n, "MCALL takes one cycle call and nothing else")
            return
        if self.mcall is not None:
            self.problem(n, "MCALL while MCALL %s (line %d) is active" % (self.mcall["cycle"], self.mcall["line"]))
        params = self.cycle_parameters(n, words[1][1])
        if params is not None:
            self.mcall = params

    def cycle_position(self, n, seen):
        c = self.mcall
        if self.motion not in (0, 1):
            self.problem(n, "an arc while MCALL %s is active" % c["cycle"])
            return
        if "Z" in seen or any(a in seen for a in ("I", "J", "K", "CR", "TURN")):
            self.problem(n, "a position block under MCALL with more than X and Y")
        z = self.pos["Z"]
        if z is None or z < c["r"] - 1e-9:
            self.problem(n, "a position under MCALL %s from %s, below the reference plane %g" % (
                c["cycle"], "an unknown height" if z is None else "z=%g" % z, c["r"]))
        self.ready_to_move(n, True, need_feed=c["cycle"] != "CYCLE84")
        for axis in "XY":
            if axis in seen:
                self.pos[axis] = seen[axis]
        self.make(n, "rapid", 0)
        if self.pos["X"] is None or self.pos["Y"] is None:
            self.problem(n, "a hole at an unknown position")
        else:
            self.drill(n, c)
        c["holes"] += 1
        self.counts["holes"] += 1

    def drill(self, n, c):
        """The moves a drilling cycle makes where the tool is, as its documented parameters say; the tool
        ends at RTP."""
        x, y = self.pos["X"], self.pos["Y"]
        values = c["values"]

        def at(z):
            return (x, y, z)
        self.make(n, "rapid", 0, at(c["r"]))
        if c["cycle"] == "CYCLE83" and len(values) > 11 and values[11] == 1:
            # Full retract (VARI 1) after each stroke; strokes as long as the
            # first (no degression, DAM 0), the last one shorter. The way
            # back down is the controller's: only the feed moves are compared.
            first = values[5] if values[5] is not None else c["rfp"] - values[6]
            stroke = c["rfp"] - first
            if (values[7] or 0) != 0 or stroke <= 0:
                self.problem(n, "CYCLE83 with degression or no first stroke: not modelled")
                return
            bottom = first
            while True:
                bottom = max(bottom, c["depth"])
                self.make(n, "linear", self.feed, at(bottom))
                if bottom <= c["depth"] + 1e-9:
                    break
                self.make(n, "rapid", 0, at(c["r"]))
                bottom -= stroke
        elif c["cycle"] == "CYCLE84":
            pitch, sst, sst1 = abs(values[8] or 0), values[10] or 0, values[11] or values[10] or 0
            self.make(n, "linear", pitch * sst, at(c["depth"]))
            self.make(n, "linear", pitch * sst1, at(c["r"]))
        elif c["cycle"] == "CYCLE81":
            self.make(n, "linear", self.feed, at(c["depth"]))
        elif c["cycle"] == "CYCLE82":
            # As CYCLE81, waiting DTB seconds at the bottom.
            self.make(n, "linear", self.feed, at(c["depth"]))
            if values[5]:
                self.made.append(dict(kind="dwell", to=at(c["depth"]), time=values[5], feed=0, line=n))
        else:
            self.problem(n, "%s: its moves are not modelled" % c["cycle"])
        self.pos["Z"] = c["rtp"]
        self.make(n, "rapid", 0)

    def swivel_call(self, n, args, nwords):
        """CYCLE800 in the one form stepnc writes (README.md, "3+2"): _FR 0,
        _TC a name ("0": deselect, every value 0), _ST 0, _MODE 27 (axis by
        axis, Z then Y then X), X0 Y0 Z0 0, the angles, the rotated zero X1
        Y1 Z1, _DIR -1, _FR_I 0; alone, right after G0 SUPA Z.."""
        if nwords != 1:
            self.problem(n, "CYCLE800 shares its block")
        if len(args) != 15:
            self.problem(n, "CYCLE800 with %d arguments (it takes 15)" % len(args))
            return
        tc = args[1]
        if not re.fullmatch(r'"[A-Za-z0-9_]+"', tc):
            self.problem(n, "CYCLE800: _TC %s is not a name in double quotes" % tc)
            return
        try:
            v = [arg_number(a) for k, a in enumerate(args) if k != 1]
        except ValueError as e:
            self.problem(n, "CYCLE800: argument %r is not a plain number" % str(e))
            return
        # v: _FR, _ST, _MODE, X0, Y0, Z0, A, B, C, X1, Y1, Z1, _DIR, _FR_I
        if v[0] != 0 or v[1] != 0 or v[2] != 27 or any(v[3:6]) or v[12] != -1 or v[13] != 0:
            self.problem(n, "CYCLE800 not of the form CYCLE800(0,\"..\",0,27,0.,0.,0.,A,B,C,X1,Y1,Z1,-1,0.)")
        deselect = tc == '"0"'
        if deselect and any(v[6:12]):
            self.problem(n, "CYCLE800: a deselection (_TC \"0\") with angles or a zero point")
        if self.traori:
            self.problem(n, "CYCLE800 with TRAORI on")
        if self.up is None:
            self.problem(n, "CYCLE800 swivels without the tool first up (G0 SUPA Z..) and nothing moved since")
        self.turns.append({"where": "line %d" % n, "z": self.up})
        self.swivel = None if deselect else (tuple(v[6:9]), tuple(v[9:12]))
        self.pos = {"X": None, "Y": None, "Z": None}

    def direct_call(self, n, call, nwords):
        name, args = cycle_args(call)
        if name == "CYCLE800":
            self.swivel_call(n, args, nwords)
            return
        if name == "CYCLE832":
            if nwords != 1:
                self.problem(n, "CYCLE832 shares its block")
            if len(args) != 3:
                self.problem(n, "CYCLE832 with %d arguments (it takes 3: _TOL, _TOLM, _OTOL)" % len(args))
                return
            try:
                tol, mode, otol = (arg_number(a) for a in args)
            except ValueError as e:
                self.problem(n, "CYCLE832: argument %r is not a plain number" % str(e))
                return
            if mode not in (0, 1, 2, 3):
                self.problem(n, "CYCLE832: _TOLM is 0 (off), 1, 2 or 3, not %s" % args[1])
            elif mode != 0 and not (tol and tol > 0):
                self.problem(n, "CYCLE832: a tolerance above 0 is needed with _TOLM %s" % args[1])
            if otol != 1:
                self.problem(n, "CYCLE832: _OTOL is 1 on a 3-axis machine, not %s" % args[2])
            return
        # A direct (not modal) drilling cycle runs once where the tool is.
        params = self.cycle_parameters(n, call)
        if params is None:
            return
        if nwords != 1:
            self.problem(n, "%s shares its block" % name)
        z = self.pos["Z"]
        if None in self.pos.values() or z < params["r"] - 1e-9:
            self.problem(n, "%s called from an unknown position or below its reference plane" % name)
        self.ready_to_move(n, True, need_feed=name != "CYCLE84")
        if None not in self.pos.values():
            self.drill(n, params)
        self.counts["holes"] += 1


def check_text(name, text, max_line, codes=()):
    """The checker after reading `text`, its problems in c.problems."""
    lines = text.split("\n")
    last_newline = lines and lines[-1] == ""
    if last_newline:
        lines.pop()
    c = Checker(name, lines, max_line, codes)
    c.run()
    if not last_newline:
        c.problems.append("%s:%d: the last line has no newline" % (name, len(lines)))
    return c


def compile_input(stepnc, path, options, directory):
    """The program and the toolpath IR stepnc makes of `path`, or the compiler's error text."""
    stem = os.path.splitext(os.path.basename(path))[0]
    os.makedirs(directory, exist_ok=True)
    program = os.path.join(directory, stem + ".mpf")
    ir = os.path.join(directory, stem + ".ir")
    for output, extra in ((program, []), (ir, ["--emit=toolpath-ir"])):
        r = subprocess.run([stepnc, "compile", path, "--target=siemens-840d", "-o", output] + options + extra,
                           capture_output=True, text=True)
        if r.returncode != 0:
            return None, None, r.stderr.strip()
    return program, ir, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", help="programs (or, with --stepnc, inputs to compile)")
    ap.add_argument("--max-line-length", type=int, default=512, help="longest line allowed (0: no limit)")
    ap.add_argument("--ir", help="toolpath IR whose moves the (one) program must make")
    ap.add_argument("--stepnc", help="compile each input with this stepnc first, and compare its moves with the "
                    "toolpath IR")
    ap.add_argument("--option", action="append", default=[],
                    help="an option for stepnc compile (repeatable), e.g. --option=--no-cycles")
    ap.add_argument("--machine", help="the machine whose [deposition] codes the programs write (a file or a "
                    "shipped name; default: the --machine of --option)")
    args = ap.parse_args()
    if args.ir and (args.stepnc or len(args.files) != 1):
        ap.error("--ir goes with one program and no --stepnc")
    machine = args.machine or next((o.split("=", 1)[1] for o in args.option if o.startswith("--machine=")), None)
    codes = deposition_codes(machine)
    if isinstance(codes, str):
        ap.error(codes)

    failed = False
    suffix = " (%s)" % " ".join(args.option) if args.option else ""
    with tempfile.TemporaryDirectory(prefix="check-siemens-840d.") as tmp:
        for i, path in enumerate(args.files):
            name, ir = os.path.basename(path), args.ir
            if args.stepnc:
                path, ir, error = compile_input(args.stepnc, path, args.option, os.path.join(tmp, str(i)))
                if path is None:
                    print("FAIL: %s%s: stepnc compile failed:\n%s" % (name, suffix, error))
                    failed = True
                    continue
            with open(path, newline="") as f:
                c = check_text(name, f.read(), args.max_line_length, codes)
            problems = list(c.problems)
            compared = ""
            if ir and not problems:
                # Moves that tilt the tool (under TRAORI) are check-tcp.py's.
                moves = [m for m in planned_moves(ir) if m.get("axis", (0.0, 0.0, 1.0)) == (0.0, 0.0, 1.0)]
                made = [m for m in c.made if not m.get("tcp")]
                differences, count = compare_moves(moves, made, feeds_only=c.counts["holes"] > 0)
                problems += ["%s: %s" % (name, d) for d in differences]
                compared = ", %d planned moves made" % count
            if problems:
                failed = True
                print("FAIL: %s%s: %d problems" % (name, suffix, len(problems)))
                for p in problems:
                    print("  " + p)
            else:
                print("ok: %s%s: %d blocks, %d moves, %d I/J arcs (%d with TURN=), %d CR= arcs, %d cycle holes%s" % (
                    name, suffix, c.counts["blocks"], c.counts["moves"], c.counts["ijk"], c.counts["turn"],
                    c.counts["cr"], c.counts["holes"], compared))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
