#!/usr/bin/env python3
"""Part 21 -> Part 28 -> Part 21, for each file given, through `stepnc convert`.

For each file: the XML is written; with --xsd DIR it is validated with
`xmllint --schema` against the XSD stepnc generated for its schema; it is
converted back, and the Part 21 must equal the canonical Part 21 of the
original byte for byte, or differ only in entity names written through an
alias (then the count of such instances is reported); with --target, the
original and the XML are compiled and the programs must be identical but for
the comment naming the input file. One line per file: "ok: NAME: ..." or
"FAIL: NAME: ..."; the exit status is 1 when any file fails.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile


def run(cmd):
    return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def without_names(text):
    """The Part 21 text with each instance's entity name blanked out."""
    return re.sub(r"^(#\d+=)[A-Z0-9_]+\(", r"\1(", text, flags=re.M)


def program_lines(path, source_name):
    with open(path, encoding="utf-8") as f:
        return [line for line in f if source_name not in line]


def check(args, path, work):
    name = os.path.basename(path)
    stem = os.path.join(work, re.sub(r"[^A-Za-z0-9_.-]", "_", name))
    canonical, xml, back = stem + ".stp", stem + ".stpx", stem + ".back.stp"
    for cmd in ([args.stepnc, "convert", path, "-o", canonical], [args.stepnc, "convert", path, "-o", xml],
                [args.stepnc, "convert", xml, "-o", back]):
        r = run(cmd)
        if r.returncode != 0:
            return "FAIL: %s: %s exited %d: %s" % (name, " ".join(cmd[1:2]), r.returncode, r.stderr.strip())
    notes = []
    if args.xsd:
        with open(xml, encoding="utf-8") as f:
            m = re.search(r'<uos xmlns="urn:iso10303-28:xs/([a-z0-9_]+)"', f.read())
        if not m:
            return "FAIL: %s: no uos namespace in the XML" % name
        r = run(["xmllint", "--noout", "--schema", os.path.join(args.xsd, m.group(1) + ".xsd"), xml])
        if r.returncode != 0:
            return "FAIL: %s: not valid against %s.xsd: %s" % (name, m.group(1), r.stderr.strip()[:2000])
        notes.append("valid")
    with open(canonical, encoding="utf-8") as f:
        expected = f.read()
    with open(back, encoding="utf-8") as f:
        got = f.read()
    if expected == got:
        notes.append("same Part 21")
    elif without_names(expected) == without_names(got):
        renamed = sum(1 for a, b in zip(expected.splitlines(), got.splitlines()) if a != b)
        notes.append("same Part 21 up to %d alias names" % renamed)
    else:
        return "FAIL: %s: the Part 21 read back differs from the original" % name
    if args.target:
        programs = []
        for source in (path, xml):
            out = stem + (".xml" if source == xml else ".p21") + ".program"
            r = run([args.stepnc, "compile", source, "--target=" + args.target, "-o", out] + args.option)
            programs.append((r.returncode, out, r.stderr))
        (rc1, out1, err1), (rc2, out2, _) = programs
        if rc1 != rc2:
            return "FAIL: %s: compiling the Part 21 exits %d, the XML %d" % (name, rc1, rc2)
        if rc1 == 0:
            p1 = program_lines(out1, name)
            p2 = program_lines(out2, os.path.basename(xml))
            if p1 != p2:
                return "FAIL: %s: the programs differ" % name
            notes.append("identical %s programs (%d lines)" % (args.target, len(p1)))
        else:
            notes.append("both refused to compile")
    return "ok: %s: %s" % (name, ", ".join(notes))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stepnc", required=True)
    parser.add_argument("--xsd", help="folder of the XSDs `stepnc schema --xsd` wrote")
    parser.add_argument("--target", help="also compile both and compare the programs")
    parser.add_argument("--option", action="append", default=[],
                        help="an option for stepnc compile (repeatable), e.g. --option=--allow-out-of-range")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    failed = False
    with tempfile.TemporaryDirectory() as work:
        for path in args.files:
            line = check(args, path, work)
            failed |= line.startswith("FAIL")
            print(line, flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
