#!/usr/bin/python3
"""check_bit_rate.py SOURCE_DIR [--also DOC.md ...]: the bus has one bit rate.

The firmware's protocol::kNominalBitrate_bit_s (firmware/protocol/messages.hpp) is the source;
the DBC file's Baudrate attribute (docs/can/drive.dbc) and every bit-rate statement in README.md,
docs/*.md and docs/can/*.md ("500 kbit/s", "1 Mbit/s", "1 Mbps", "bitrate 1000000") must say
the same. Docs are globbed, so a new page is checked as soon as it exists. --also adds files
(the test of this checker gives it a page that disagrees). Exit 0 when all agree, 1 otherwise
(each disagreement named with its file and line), 2 when the source or the DBC has no bit rate.
"""
import argparse
import glob
import os
import re
import sys

# "1 Mbit/s", "500 kbit/s", "1 Mbps", "500 kbps", "500 kBaud", "bitrate 1000000" (ip link).
STATEMENT = re.compile(
    r"(?P<value>\d+(?:\.\d+)?)\s*(?P<unit>[kM])(?:bit/s|bps|Baud)\b|\bbitrate\s+(?P<raw>\d+)")
SOURCE = "firmware/protocol/messages.hpp"
DBC = "docs/can/drive.dbc"


def firmware_bit_rate(source_dir):
    text = open(os.path.join(source_dir, SOURCE), encoding="utf-8").read()
    match = re.search(r"kNominalBitrate_bit_s\s*=\s*([\d']+)\s*;", text)
    if not match:
        sys.exit(f"check_bit_rate: {SOURCE}: no kNominalBitrate_bit_s = N;")
    return int(match.group(1).replace("'", ""))


def dbc_bit_rates(source_dir):
    """The Baudrate attribute's default and value, with their line numbers."""
    found = []
    with open(os.path.join(source_dir, DBC), encoding="utf-8") as dbc:
        for number, line in enumerate(dbc, 1):
            match = re.match(r'BA_(?:DEF_DEF_)? "Baudrate" (\d+);', line)
            if match:
                found.append((number, int(match.group(1))))
    if not found:
        sys.exit(f"check_bit_rate: {DBC}: no Baudrate attribute")
    return found


def statements(path):
    """(line number, text, bit/s) of every bit-rate statement in a Markdown file."""
    with open(path, encoding="utf-8") as doc:
        for number, line in enumerate(doc, 1):
            for match in STATEMENT.finditer(line):
                if match.group("raw"):
                    value = int(match.group("raw"))
                else:
                    scale = 1e3 if match.group("unit") == "k" else 1e6
                    value = round(float(match.group("value")) * scale)
                yield number, match.group(0), value


def text_of(bit_s):
    return f"{bit_s // 1_000_000} Mbit/s" if bit_s % 1_000_000 == 0 else f"{bit_s // 1000} kbit/s"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source_dir")
    parser.add_argument("--also", nargs="*", default=[], help="more Markdown files to check")
    args = parser.parse_args()
    root = args.source_dir
    expected = firmware_bit_rate(root)
    want = f"{SOURCE} says {text_of(expected)}"
    problems = []
    for number, value in dbc_bit_rates(root):
        if value != expected:
            problems.append(f"{DBC}:{number}: Baudrate {value}, but {want}")
    docs = [os.path.join(root, "README.md")]
    docs += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    docs += sorted(glob.glob(os.path.join(root, "docs", "can", "*.md")))
    docs += args.also
    checked = 0
    for path in docs:
        name = os.path.relpath(path, root) if path.startswith(root) else path
        for number, text, value in statements(path):
            checked += 1
            if value != expected:
                problems.append(f"{name}:{number}: \"{text}\", but {want}")
    for problem in problems:
        print(f"check_bit_rate: {problem}")
    if problems:
        print(f"check_bit_rate: {len(problems)} statements disagree with {SOURCE}")
        return 1
    print(f"check_bit_rate: the DBC and {checked} statements in {len(docs)} docs say "
          f"{text_of(expected)}, as {SOURCE} does")
    return 0


if __name__ == "__main__":
    sys.exit(main())
