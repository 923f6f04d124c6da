#!/usr/bin/env python3
"""Google Benchmark JSON of bench/codec_bench -> result rows for bench/report.py.

  codec_bench --benchmark_format=json | bench/codec_rows.py [FILE|-]

Runs nothing. Summarises codec_bench into a few rows (ns, real time): decode of one frame
(median over the packet kinds benchmarked, with the range in the note), encode of one
frame (same), and parsing one candump -L line. A benchmark of another kind gets a row of
its own. With --benchmark_repetitions the median aggregates are used.
"""
import json
import statistics
import sys

UNITS_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
# name prefix -> row title
GROUPS = [
    ("BM_Decode", "codec: decode one PMU frame"),
    ("BM_Encode", "codec: encode one PMU frame"),
    ("BM_ParseCandump", "codec: parse one candump -L line"),
]


def runs(doc):
    benches = [b for b in doc.get("benchmarks", []) if not b.get("error_occurred")]
    medians = [b for b in benches if b.get("aggregate_name") == "median"]
    if medians:
        return [(b["run_name"], b["real_time"] * UNITS_NS[b["time_unit"]]) for b in medians]
    return [(b["name"], b["real_time"] * UNITS_NS[b["time_unit"]])
            for b in benches if b.get("run_type", "iteration") == "iteration"]


def row(title, results):
    times = [ns for _, ns in results]
    names = ", ".join(name.removeprefix("BM_") for name, _ in results)
    if len(results) == 1:
        note = f"Google Benchmark {names}, real time."
    else:
        note = (f"Median of {len(results)} Google Benchmarks ({names}), real time; "
                f"range {min(times):.1f} to {max(times):.1f} ns.")
    return {"benchmark": title, "value": round(statistics.median(times), 2), "unit": "ns",
            "reference": None, "reference_name": "", "ratio": None, "target": "", "met": None,
            "note": note}


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "-"
    try:
        doc = json.load(sys.stdin if path == "-" else open(path))
    except (OSError, ValueError) as e:
        sys.exit(f"codec_rows.py: cannot read Google Benchmark JSON from {path}: {e}")
    results = runs(doc)
    if not results:
        sys.exit(f"codec_rows.py: no benchmark results in {path}")
    for prefix, title in GROUPS:
        group = [r for r in results if r[0].startswith(prefix)]
        if group:
            print(json.dumps(row(title, group)))
    for name, ns in results:
        if not any(name.startswith(prefix) for prefix, _ in GROUPS):
            print(json.dumps(row(f"codec: {name.removeprefix('BM_')}", [(name, ns)])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
