#!/usr/bin/env python3
"""Benchmark result rows (JSON lines) -> one markdown table, for the benchmark report.

  bench/report.py [FILE...]        (no FILE, or -, reads standard input)

A row: {"benchmark": "...", "value": 268801.0, "unit": "frames/s", "reference": 52000.0,
"reference_name": "...", "ratio": 5.17, "target": "ratio <= 1.25", "met": true, "note": "..."}
(reference, ratio and met may be null). {"section": "Codec"} prints a bold separator row.
Rows keep their input order; notes follow the table as a numbered list.
"""
import json
import sys

HEADER = "| benchmark | pmu-dds | reference (same run) | ratio | target | result |"
UNIT_TEXT = {"us": "µs"}


def number(v, unit):
    if unit == "frames/s":
        return f"{v:,.0f}"
    if unit == "threads":
        return f"{v:,.0f}"
    size = abs(v)
    return f"{v:,.0f}" if size >= 100 else f"{v:.1f}" if size >= 10 else f"{v:.2f}"


def quantity(v, unit):
    if v is None:
        return ""
    if unit == "x":
        return f"{number(v, unit)}x"
    return f"{number(v, unit)} {UNIT_TEXT.get(unit, unit)}".strip()


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def read_rows(paths):
    for path in paths or ["-"]:
        f = sys.stdin if path == "-" else open(path)
        for n, line in enumerate(f, start=1):
            if not line.strip():
                continue
            try:
                row = json.loads(line)
                if "section" not in row:
                    row["benchmark"], row["value"]  # required
                    if not isinstance(row["value"], (int, float)) or isinstance(row["value"], bool):
                        raise ValueError("value must be a number: every row is filled")
            except (ValueError, KeyError, TypeError) as e:
                sys.exit(f"report.py: {path}:{n}: not a result row ({e!r}): {line.strip()}")
            yield row


def main():
    rows = list(read_rows(sys.argv[1:]))  # all read first: a bad row prints no half table
    print(HEADER)
    print("|---|---|---|---|---|---|")
    notes = []
    for row in rows:
        if "section" in row:
            print(f"| **{cell(row['section'])}** | | | | | |")
            continue
        name = cell(row["benchmark"])
        if row.get("note"):
            notes.append(row["note"])
            name += f" [{len(notes)}]"
        unit = row.get("unit", "")
        reference = quantity(row.get("reference"), unit)
        if reference and row.get("reference_name"):
            reference += f" ({row['reference_name']})"
        ratio = "" if row.get("ratio") is None else f"{row['ratio']:.2f}"
        result = {True: "met", False: "MISSED"}.get(row.get("met"), "")
        print(f"| {name} | {quantity(row['value'], unit)} | {cell(reference)} | {ratio} | "
              f"{cell(row.get('target', ''))} | {result} |")
    if notes:
        print()
        for i, note in enumerate(notes, start=1):
            print(f"{i}. {note}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
