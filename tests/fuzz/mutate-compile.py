#!/usr/bin/env python3
"""Semantic mutation fuzzing of the whole compile.

Takes real STEP-NC parts (Part 21 files that compile today), changes one
thing in each copy the way a generator or a hand edit gets it wrong (a
number set to an edge value, a reference pointed elsewhere or to nothing, a
list member dropped or repeated, an enumeration changed), compiles the copy
and checks what must hold for every input, good or bad:

  * stepnc ends by itself: no signal (abort, segmentation fault), no run past
    --timeout seconds, no more memory than --memory-mb (an allocation past it
    fails, which must not abort either);
  * the exit status is 0 (a program) or 1 (errors), and every error and
    warning names a place (file:line:col), as diagnostics.md promises;
  * with errors nothing is written; with a program every number in it is
    finite (no inf, nan) and LinuxCNC's rs274 accepts it and makes the moves
    stepnc planned (tests/backends/check-rs274.py), when rs274 is installed;
  * a native plan (--native, with a machine) is read back by `stepnc sim`.

Mutants are drawn from --seed, so a run is repeatable; each failing mutant
is written to --out with what failed. Exit status 0 when every mutant held,
1 otherwise, 2 on a usage error.

  tests/fuzz/mutate-compile.py --stepnc build/bin/stepnc --count 200 \\
      --seed 1 --out /tmp/mutants examples/*.stp ../shared/corpus
"""
import argparse
import contextlib
import importlib.util
import io
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# Edge values a number is set to: zero, signs, the tiny and the huge, values
# no part has, and the limits of a double.
EDGE_VALUES = ["0.", "-1.", "1.E-09", "5.E-09", "0.001", "-0.001", "1.E+05", "1.E+06", "-1.E+06", "1.E+308",
               "-1.E+308", "1.7976931348623157E+308", "123.456", "0.7071", "-50.", "360.", "3.14159", "1.E-300"]

INSTANCE_RE = re.compile(r"^#(\d+)\s*=\s*(.*);\s*$")
# A number that is a whole parameter: after '(' or ',' and before ',' or ')'.
NUMBER_RE = re.compile(r"(?<=[(,])\s*(-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)\s*(?=[,)])")
REF_RE = re.compile(r"(?<=[(,])\s*#(\d+)\s*(?=[,)])")
ENUM_RE = re.compile(r"(?<=[(,])\s*\.([A-Z_]+)\.\s*(?=[,)])")
LIST_RE = re.compile(r"\(((?:#\d+\s*,\s*)+#\d+)\)")
ENUM_VALUES = ["T", "F", "U", "CW", "CCW", "CLIMB", "CONVENTIONAL", "LEFT", "RIGHT", "TCP", "CCP", "FLAT",
               "OPEN", "RADIUSED", "LOOP_BACK", "STRAIGHTLINE", "X_AXIS_NOT_AN_ENUM"]

LOCATED = re.compile(r"^\S.*?:\d+:\d+: (error|warning): ")
UNLOCATED = re.compile(r"^(stepnc: error: |error: |warning: )")
NOT_FINITE = re.compile(r"\b(inf|nan)\b", re.IGNORECASE)


def load_check_rs274():
    path = os.path.join(HERE, "..", "backends", "check-rs274.py")
    sys.path.insert(0, os.path.dirname(path))
    spec = importlib.util.spec_from_file_location("check_rs274", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def part21_files(paths):
    out = []
    for p in paths:
        if os.path.isdir(p):
            for root, _, files in os.walk(p):
                for f in files:
                    if f.lower().endswith((".stp", ".p21", ".step", ".stpnc")):
                        out.append(os.path.join(root, f))
        else:
            out.append(p)
    return sorted(out)


def mutate(text, rng):
    """One mutation of `text`: (the mutated text, what was changed)."""
    lines = text.split("\n")
    data = [i for i, l in enumerate(lines) if INSTANCE_RE.match(l)]
    ids = [INSTANCE_RE.match(lines[i]).group(1) for i in data]
    for _ in range(100):
        i = rng.choice(data)
        line = lines[i]
        kind = rng.choice(["number", "number", "number", "ref", "list", "enum"])
        if kind == "number":
            spans = [m.span(1) for m in NUMBER_RE.finditer(line)]
            if not spans:
                continue
            a, b = rng.choice(spans)
            value = rng.choice(EDGE_VALUES + ["$"])
            what = "number %s -> %s" % (line[a:b], value)
            lines[i] = line[:a] + value + line[b:]
        elif kind == "ref":
            spans = [m.span(1) for m in REF_RE.finditer(line)]
            if not spans:
                continue
            a, b = rng.choice(spans)
            target = rng.choice(ids + ["99999"]) if rng.random() < 0.8 else None
            value = "$" if target is None else target
            what = "reference #%s -> %s" % (line[a:b], value if target is None else "#" + value)
            lines[i] = line[:a - 1] + ("$" if target is None else "#" + target) + line[b:]
        elif kind == "list":
            lists = list(LIST_RE.finditer(line))
            if not lists:
                continue
            m = rng.choice(lists)
            members = [s.strip() for s in m.group(1).split(",")]
            j = rng.randrange(len(members))
            if rng.random() < 0.5:
                what = "list member %s dropped" % members[j]
                del members[j]
            else:
                what = "list member %s repeated" % members[j]
                members.insert(j, members[j])
            lines[i] = line[:m.start(1)] + ",".join(members) + line[m.end(1):]
        else:
            spans = [m.span(1) for m in ENUM_RE.finditer(line)]
            if not spans:
                continue
            a, b = rng.choice(spans)
            value = rng.choice(ENUM_VALUES)
            what = "enumeration .%s. -> .%s." % (line[a:b], value)
            lines[i] = line[:a] + value + line[b:]
        return "\n".join(lines), "line %d: %s" % (i + 1, what)
    return None, None


def limit_memory(mb):
    def apply():
        if mb > 0:  # 0: none (AddressSanitizer reserves terabytes of address space)
            resource.setrlimit(resource.RLIMIT_AS, (mb << 20, mb << 20))
    return apply


def run(cmd, timeout, memory_mb):
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, preexec_fn=limit_memory(memory_mb),
                           errors="replace")
        return r.returncode, r.stdout, r.stderr
    except subprocess.TimeoutExpired:
        return None, "", ""


def check_mutant(args, path, workdir, rs274):
    """What failed for the mutant at `path` (empty when everything held)."""
    problems = []
    out = os.path.join(workdir, "prog.ngc")
    if os.path.exists(out):
        os.remove(out)
    cmd = [args.stepnc, "compile", path, "--target=rs274", "-o", out]
    rc, _, err = run(cmd, args.timeout, args.memory_mb)
    if rc is None:
        return ["compile ran past %d s" % args.timeout]
    if rc < 0 or rc not in (0, 1):
        problems.append("compile ended with status %d" % rc)
    for line in err.splitlines():
        if UNLOCATED.match(line):
            problems.append("unlocated: " + line)
    if rc != 0 and os.path.exists(out):
        problems.append("errors, yet %s was written" % out)
    if rc == 0:
        with open(out, errors="replace") as f:
            program = f.read()
        bad = [l for l in program.splitlines() if not l.startswith("(") and NOT_FINITE.search(l)]
        if bad:
            problems.append("a number that is not finite: " + bad[0])
        if rs274 and not bad:
            with contextlib.redirect_stdout(io.StringIO()):  # its "ok: ..." lines
                found = rs274.check(args.stepnc, path, True, [], workdir, program=out)
            problems += ["rs274: " + p for p in found]
    if args.native and rc == 0:
        motion = os.path.join(workdir, "prog.motion")
        rc, _, err = run([args.stepnc, "compile", path, "--target=native", "--machine", args.native, "-o", motion],
                         args.timeout, args.memory_mb)
        if rc is None or rc < 0 or rc not in (0, 1):
            problems.append("native compile ended with %s" % ("a timeout" if rc is None else "status %d" % rc))
        elif rc == 0:
            rc, _, err = run([args.stepnc, "sim", motion, "--machine", args.native], args.timeout, args.memory_mb)
            if rc is None or rc != 0:
                problems.append("sim refused the native plan compile wrote:\n" + err[-2000:])
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stepnc", required=True)
    ap.add_argument("--count", type=int, default=100, help="mutants to run")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=int, default=60, help="seconds per compile")
    ap.add_argument("--memory-mb", type=int, default=4096, help="address space per compile; 0 for no limit (sanitizer builds)")
    ap.add_argument("--out", help="directory for failing mutants (default: a temporary one, kept on failure)")
    ap.add_argument("--native", metavar="MACHINE", help="also plan natively for this machine and run sim")
    ap.add_argument("--no-rs274", action="store_true", help="do not run LinuxCNC's rs274")
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--replay", action="store_true",
                    help="check the inputs themselves (kept mutants), without mutating them")
    ap.add_argument("inputs", nargs="+", help="STEP-NC files or directories of them")
    args = ap.parse_args()

    rng = random.Random(args.seed)
    seeds = []
    for path in part21_files(args.inputs):
        with open(path, errors="replace") as f:
            text = f.read()
        if INSTANCE_RE.search(text.replace("\r", "")) or "DATA;" in text:
            seeds.append((path, text.replace("\r\n", "\n")))
    if not seeds:
        print("mutate-compile: no STEP-NC inputs", file=sys.stderr)
        return 2
    rs274 = None if args.no_rs274 or not shutil.which("rs274") else load_check_rs274()
    if args.replay:
        failed = 0
        with tempfile.TemporaryDirectory() as workdir:
            for path in part21_files(args.inputs):
                problems = check_mutant(args, path, workdir, rs274)
                failed += bool(problems)
                print("%s %s%s" % ("FAIL" if problems else "ok", path, "".join("\n  " + p for p in problems)))
        print("mutate-compile: %d replayed, %d failed" % (len(part21_files(args.inputs)), failed))
        return 1 if failed else 0
    if rs274 is None and not args.quiet:
        print("mutate-compile: rs274 not used (%s)" % ("--no-rs274" if args.no_rs274 else "not installed"))
    out = args.out or tempfile.mkdtemp(prefix="stepnc-mutants-")
    os.makedirs(out, exist_ok=True)
    failed = 0
    with tempfile.TemporaryDirectory() as workdir:
        for n in range(args.count):
            source, text = rng.choice(seeds)
            mutant, what = mutate(text, rng)
            if mutant is None:
                continue
            path = os.path.join(workdir, "mutant.stp")
            with open(path, "w") as f:
                f.write(mutant)
            problems = check_mutant(args, path, workdir, rs274)
            name = "%s-%d" % (os.path.splitext(os.path.basename(source))[0].replace(" ", "_"), n)
            if problems:
                failed += 1
                keep = os.path.join(out, name + ".stp")
                shutil.copy(path, keep)
                with open(keep + ".txt", "w") as f:
                    f.write("from %s, %s\n%s\n" % (source, what, "\n".join(problems)))
                print("FAIL %s (%s, %s)\n  %s" % (keep, os.path.basename(source), what, "\n  ".join(problems)))
            elif not args.quiet:
                print("ok %d %s: %s" % (n, os.path.basename(source), what))
    print("mutate-compile: %d mutants, %d failed%s" % (args.count, failed,
                                                         "; kept in " + out if failed else ""))
    if not failed and not args.out:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
