#!/usr/bin/env python3
"""Runs every Part 21 file of the sample corpus through `stepnc compile F
--target=rs274 -o TMP` and `stepnc check F`, and prints for each run its exit
status and how many located errors and warnings it gave:

    FILE compile: exit 1, 1 error, 0 warnings

then every line of standard error that is an error or a warning without a
location (`stepnc: error: ...`, `error: ...`, `warning: ...`), as

    UNLOCATED FILE compile: stepnc: error: ...

Notes are left out: they belong to the diagnostic before them. Used by
corpus-located.test.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

LOCATED = re.compile(r"^\S.*?:\d+:\d+: (error|warning): ")
UNLOCATED = re.compile(r"^(stepnc: error: |error: |warning: )")


def part21_files(corpus):
    out = []
    for root, _, files in os.walk(corpus):
        for f in files:
            path = os.path.join(root, f)
            if f.endswith((".md", ".exp", ".txt")):
                continue  # the corpus's notes and schemas
            with open(path, "rb") as fh:
                if b"ISO-10303-21;" in fh.read(4096):
                    out.append(path)
    return sorted(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--stepnc", required=True)
    ap.add_argument("corpus")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as work:
        for path in part21_files(args.corpus):
            name = os.path.relpath(path, args.corpus)
            runs = {"compile": [args.stepnc, "compile", path, "--target=rs274", "-o", os.path.join(work, "x.ngc")],
                    "check": [args.stepnc, "check", path]}
            for what, cmd in runs.items():
                r = subprocess.run(cmd, capture_output=True, text=True)
                lines = r.stderr.splitlines()
                errors = sum(1 for l in lines if (m := LOCATED.match(l)) and m.group(1) == "error")
                warnings = sum(1 for l in lines if (m := LOCATED.match(l)) and m.group(1) == "warning")
                print("%s %s: exit %d, %d error%s, %d warning%s" % (name, what, r.returncode, errors,
                      "" if errors == 1 else "s", warnings, "" if warnings == 1 else "s"))
                for l in lines:
                    if UNLOCATED.match(l):
                        print("UNLOCATED %s %s: %s" % (name, what, l))
    return 0


if __name__ == "__main__":
    sys.exit(main())
