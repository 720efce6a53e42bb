#!/usr/bin/env python3
"""Markdown table (median, min, max per iteration; samples/s) from criterion's saved
samples: `python3 bench/criterion_table.py [TARGET_DIR/criterion]` after `cargo bench`.
Criterion's own printout gives a confidence interval of the mean slope, not min/max."""
import json
import os
import statistics
import sys


def fmt_t(s):
    for unit, f in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6), ("ns", 1e-9)):
        if s >= f:
            return f"{s / f:.3g} {unit}"
    return f"{s / 1e-9:.3g} ns"


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.environ.get("CARGO_TARGET_DIR", "target"), "criterion")
    rows = []
    for d, _, files in os.walk(root):
        if os.path.basename(d) != "new" or "sample.json" not in files:
            continue
        b = json.load(open(os.path.join(d, "benchmark.json")))
        s = json.load(open(os.path.join(d, "sample.json")))
        per = [t / i * 1e-9 for t, i in zip(s["times"], s["iters"])]
        el = (b.get("throughput") or {}).get("Elements")
        rows.append((b["full_id"], statistics.median(per), min(per), max(per), el, len(per)))
    rows.sort()
    print("| benchmark | median | min | max | samples | IMU samples/s (median) |")
    print("|---|---|---|---|---|---|")
    for name, med, lo, hi, el, n in rows:
        rate = f"{el / med / 1e6:.2f} M" if el else ""
        print(f"| {name} | {fmt_t(med)} | {fmt_t(lo)} | {fmt_t(hi)} | {n} | {rate} |")


if __name__ == "__main__":
    main()
