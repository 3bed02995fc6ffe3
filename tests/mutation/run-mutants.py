#!/usr/bin/env python3
"""Mutation testing: does the test suite notice a realistic defect?

Applies each one-line mutant of mutants.json to the source tree in turn,
rebuilds stepnc and its unit tests, runs the tests the mutant names (unit
test tags, lit paths under tests/), and restores the source. A mutant is
killed when a test fails, and survives when all pass: the suite would not
have noticed the defect. The report is a Markdown table (docs/testing.md,
"Mutation testing", keeps the last one).

    python3 tests/mutation/run-mutants.py --build build [--only ID ...] [--report FILE]

Run from the repository's root, on a clean tree (the mutants are applied to
it and undone; an interrupted run is undone too). Not part of CI: each
mutant rebuilds and links, about a minute on two cores.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd, cwd=ROOT, timeout=1800):
    try:
        p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=timeout)
        return p.returncode, p.stdout
    except subprocess.TimeoutExpired:
        return -1, "timed out"


def lit_path(build):
    with open(os.path.join(build, "CMakeCache.txt")) as f:
        for line in f:
            if line.startswith("STEPNC_LIT:"):
                return line.split("=", 1)[1].strip()
    sys.exit("run-mutants: no STEPNC_LIT in the build's CMakeCache.txt")


def failed_tests(output):
    """The names lit and Catch2 give failing tests, for the report."""
    names = []
    for line in output.splitlines():
        line = line.strip()
        if line.startswith("stepnc :: "):
            names.append(line[len("stepnc :: "):])
        elif line.startswith("FAIL: stepnc :: "):
            names.append(line[len("FAIL: stepnc :: "):].split(" (")[0])
    return sorted(set(names))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="the build directory (Release)")
    ap.add_argument("--mutants", default=os.path.join(ROOT, "tests", "mutation", "mutants.json"))
    ap.add_argument("--only", nargs="*", help="mutant ids to run")
    ap.add_argument("--report", help="write the Markdown report here too")
    ap.add_argument("-j", type=int, default=2, help="build and lit jobs")
    args = ap.parse_args()

    build = os.path.abspath(args.build)
    lit = lit_path(build)
    with open(args.mutants) as f:
        mutants = json.load(f)
    if args.only:
        mutants = [m for m in mutants if m["id"] in args.only]
    rows = []
    for m in mutants:
        path = os.path.join(ROOT, m["file"])
        with open(path) as f:
            original = f.read()
        count = original.count(m["find"])
        if count != 1:
            rows.append((m, "INVALID", f"the text to change occurs {count} times", 0))
            print(f"{m['id']}: INVALID ({count} matches)", flush=True)
            continue
        start = time.time()
        try:
            with open(path, "w") as f:
                f.write(original.replace(m["find"], m["replace"]))
            rc, out = run(["cmake", "--build", build, "-j", str(args.j), "--target", "stepnc", "stepnc-unit-tests"])
            if rc != 0:
                status, by = "killed", "the compiler"
            else:
                status, by = "SURVIVED", ""
                if m.get("unit"):
                    rc, out = run([os.path.join(build, "bin", "stepnc-unit-tests"), m["unit"]])
                    if rc != 0:
                        status, by = "killed", "unit tests " + m["unit"]
                if status == "SURVIVED" and m.get("lit"):
                    paths = [os.path.join(build, "tests", p) for p in m["lit"]]
                    rc, out = run([sys.executable, lit, "-q", "-j", str(args.j)] + paths)
                    if rc != 0:
                        status, by = "killed", ", ".join(failed_tests(out)) or "lit"
        finally:
            with open(path, "w") as f:
                f.write(original)
        seconds = time.time() - start
        rows.append((m, status, by, seconds))
        print(f"{m['id']}: {status} {by} ({seconds:.0f} s)", flush=True)
    # Rebuild what the last mutant left behind, and drop the outputs the
    # mutants' test runs wrote (a test that checks that nothing is written
    # would find one left by a mutant that wrote it).
    run(["cmake", "--build", build, "-j", str(args.j), "--target", "stepnc", "stepnc-unit-tests"])
    for dirpath, dirnames, _ in os.walk(os.path.join(build, "tests")):
        if "Output" in dirnames:
            shutil.rmtree(os.path.join(dirpath, "Output"), ignore_errors=True)
            dirnames.remove("Output")

    lines = ["| mutant | area | the defect | result | killed by |", "|---|---|---|---|---|"]
    for m, status, by, _ in rows:
        lines.append(f"| `{m['id']}` | {m['area']} | {m['what']} | {status} | {by} |")
    killed = sum(1 for _, s, _, _ in rows if s == "killed")
    lines.append("")
    lines.append(f"{killed} of {len(rows)} killed, {sum(1 for _, s, _, _ in rows if s == 'SURVIVED')} survived "
                 f"({sum(r[3] for r in rows) / 60:.0f} min).")
    report = "\n".join(lines) + "\n"
    print(report)
    if args.report:
        with open(args.report, "w") as f:
            f.write(report)
    return 0 if all(s != "SURVIVED" for _, s, _, _ in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
