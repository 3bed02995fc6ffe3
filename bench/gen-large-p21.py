#!/usr/bin/env python3
"""Make a large ISO 10303-21 file from a small one, for benchmarking readers.

    gen-large-p21.py INPUT.stp OUTPUT.stp --size-mb 100

The output keeps INPUT's text up to the end of its first `DATA;` (or
`DATA(...);`) statement and from its `ENDSEC;` on, and repeats the DATA
section's body (instances, layout and comments) as often as needed for the
output to reach the requested size. Copy k (k = 0, 1, ...) has every instance
name `#n` that is defined in that section shifted by k * (max_id + 1), in
definitions and references alike, where max_id is the largest `#n` anywhere in
INPUT; copy 0 is the original text. `#n` inside strings and comments is left
alone, and so are references to ids the section does not define (for example
ids from an ed. 3 REFERENCE section), so the output is exactly as valid as the
input and its ids stay as dense as the input's.

Sizes are in MB = 10^6 bytes. Only the Python 3 standard library is used.
"""

import argparse
import os
import re
import sys

# One token of Part 21 text. Strings ('' doubles a quote) and comments are
# tokens of their own so that `#n` and keywords inside them are never seen.
# An unterminated string or comment is matched to the end of the input by the
# fallback alternatives (the input is then broken anyway; we report it).
TOKEN = re.compile(
    r"""
    (?P<string>'(?:[^']|'')*')
  | (?P<comment>/\*.*?\*/)
  | (?P<id>\#(?P<digits>[0-9]+))
  | (?P<word>[A-Za-z_!][A-Za-z0-9_\-]*)
  | (?P<space>\s+)
  | (?P<badstring>'.*\Z)
  | (?P<badcomment>/\*.*\Z)
  | (?P<other>.)
    """,
    re.VERBOSE | re.DOTALL,
)


class InputError(Exception):
    pass


def scan(text):
    """Yields (kind, start, end, value) for every token of `text`."""
    for m in TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "digits":  # lastgroup is the innermost group
            kind = "id"
        if kind in ("badstring", "badcomment"):
            what = "string" if kind == "badstring" else "comment"
            line = text.count("\n", 0, m.start()) + 1
            raise InputError(f"unterminated {what} at line {line}")
        if kind == "id":
            yield kind, m.start(), m.end(), int(m.group("digits"))
        else:
            yield kind, m.start(), m.end(), m.group(kind)


def split_data_section(text):
    """Returns (body_start, body_end, tokens_in_body, max_id, data_sections).

    body_start is just after the first DATA statement's ';', body_end at the
    first following statement-initial ENDSEC. max_id is the largest `#n`
    anywhere in the file.
    """
    at_statement_start = True
    body_start = body_end = None
    in_data_header = False
    data_sections = 0
    body_tokens = []
    max_id = -1
    for kind, start, end, value in scan(text):
        if kind in ("space", "comment"):
            if body_start is not None and body_end is None and kind == "comment":
                body_tokens.append((kind, start, end, value))
            continue
        if kind == "id":
            max_id = max(max_id, value)
        if body_start is not None and body_end is None:
            if at_statement_start and kind == "word" and value == "ENDSEC":
                body_end = start
            else:
                body_tokens.append((kind, start, end, value))
        elif at_statement_start and kind == "word" and value == "DATA":
            data_sections += 1
            if body_start is None:
                in_data_header = True
        if in_data_header and kind == "other" and value == ";":
            in_data_header = False
            body_start = end
        at_statement_start = kind == "other" and value == ";"
    if body_start is None:
        raise InputError("no DATA section found")
    if body_end is None:
        raise InputError("the DATA section has no ENDSEC")
    return body_start, body_end, body_tokens, max_id, data_sections


def make_template(text, body_start, body_end, body_tokens):
    """The DATA body as a %-format string with one %d per shifted id."""
    # Ids defined in the body: `#n` directly followed (after layout) by '='.
    defined = set()
    prev_id = None
    for kind, _start, _end, value in body_tokens:
        if kind == "comment":
            continue
        if prev_id is not None and kind == "other" and value == "=":
            defined.add(prev_id)
        prev_id = value if kind == "id" else None
    pieces = []
    ids = []
    pos = body_start
    for kind, start, end, value in body_tokens:
        if kind != "id" or value not in defined:
            continue
        pieces.append(text[pos:start].replace("%", "%%"))
        pieces.append("#%d")
        ids.append(value)
        pos = end
    pieces.append(text[pos:body_end].replace("%", "%%"))
    return "".join(pieces), ids, len(defined)


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Repeat a Part 21 file's DATA section with shifted instance ids "
        "until the output reaches a given size.")
    ap.add_argument("input", help="Part 21 file to repeat (read only)")
    ap.add_argument("output", help="file to write ('-' for standard output)")
    ap.add_argument("--size-mb", type=float, default=100.0,
                    help="minimum output size in MB (10^6 bytes); default 100")
    ap.add_argument("--copies", type=int, default=None,
                    help="write exactly this many copies (>= 1) of the DATA section instead")
    ap.add_argument("--quiet", action="store_true", help="print nothing on success")
    args = ap.parse_args(argv)
    if args.copies is not None and args.copies < 1:
        ap.error("--copies must be at least 1")

    with open(args.input, "rb") as f:
        # Latin-1 maps every byte to one character and back: the output keeps
        # the input's bytes exactly (UTF-8 in strings included).
        text = f.read().decode("latin-1")
    try:
        body_start, body_end, body_tokens, max_id, data_sections = split_data_section(text)
    except InputError as e:
        print(f"gen-large-p21: {args.input}: {e}", file=sys.stderr)
        return 1
    template, ids, ndefined = make_template(text, body_start, body_end, body_tokens)
    prefix = text[:body_start].encode("latin-1")
    suffix = text[body_end:].encode("latin-1")
    if ndefined == 0:
        print(f"gen-large-p21: {args.input}: the DATA section defines no instances",
              file=sys.stderr)
        return 1
    if data_sections > 1:
        print(f"gen-large-p21: warning: {args.input} has {data_sections} DATA sections; "
              "only the first is repeated", file=sys.stderr)

    target = int(args.size_mb * 1e6)
    stride = max_id + 1

    out = sys.stdout.buffer if args.output == "-" else open(args.output + ".part", "wb")
    written = 0
    try:
        out.write(prefix)
        written += len(prefix)
        # Copies until the output (with the suffix) reaches the target size;
        # shifted ids get longer, so the count is decided as we go.
        copies = 0
        while (copies < args.copies if args.copies is not None
               else copies == 0 or written + len(suffix) < target):
            off = copies * stride
            chunk = (template % tuple(i + off for i in ids)).encode("latin-1")
            out.write(chunk)
            written += len(chunk)
            copies += 1
        out.write(suffix)
        written += len(suffix)
    finally:
        if out is not sys.stdout.buffer:
            out.close()
    if args.output != "-":
        os.replace(args.output + ".part", args.output)
    if not args.quiet:
        print(f"gen-large-p21: wrote {args.output}: {written / 1e6:.1f} MB, {copies} copies of "
              f"{ndefined} instances ({copies * ndefined} instances), ids shifted by "
              f"k * {stride}, largest id {(copies - 1) * stride + max_id}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
