#!/usr/bin/python3
"""Per-iteration time of liveset's step against ITK's threshold level set at equal front size.

Bins each iteration by the front it started from (ITK: the active layer after the previous
iteration; liveset: the zero layer after the previous iteration) and prints the median ms per
iteration of both programs per bin and their ratio. The first table uses liveset's growth phase
only (before its zero layer first passes 150 000 points); the second, the fronts above that, where
liveset's run goes on into convergence and lets still stretches sleep (ITK's front grows more
slowly: about 800 iterations to 200 000 points, 1 100 to 250 000, so run it with --iterations 1700).
A bin one program never reached says so.

Usage: scripts/itk_per_iteration.py ITK_LOG LIVESET_LOG   (both JSON lines, from --log)
"""
import json
import statistics
import sys

BINS = [(1000, 3000), (3000, 10000), (10000, 30000), (30000, 60000), (60000, 100000), (100000, 150000)]
LATE_BINS = [(150000, 200000), (200000, 250000), (250000, 300000), (300000, 400000)]


def read(path, front_key):
    rows = []
    try:
        with open(path) as f:
            for line in f:
                d = json.loads(line)
                if "iteration" in d and "ms" in d:
                    rows.append(d)
    except (OSError, ValueError) as e:
        sys.exit(f"itk_per_iteration: cannot read {path}: {e}")
    out, prev = [], None
    for d in rows:
        if prev is not None:
            out.append((prev, d["ms"]))
        prev = d[front_key]
    return out


def table(itk, ls, bins):
    print("| front size | ITK ms | liveset ms | ITK / liveset |")
    print("|---|--:|--:|--:|")
    for lo, hi in bins:
        a = [ms for f, ms in itk if lo <= f < hi]
        b = [ms for f, ms in ls if lo <= f < hi]
        if not a or not b:
            print(f"| {lo}-{hi} | {len(a)} ITK / {len(b)} liveset iterations | | |")
            continue
        ma, mb = statistics.median(a), statistics.median(b)
        print(f"| {lo}-{hi} | {ma:.2f} | {mb:.2f} | {ma / mb:.1f}x |")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-1])
    itk = read(sys.argv[1], "active_layer")
    ls = read(sys.argv[2], "zero_layer")
    top = BINS[-1][1]
    growth = []
    for front, ms in ls:
        if front > top:
            break
        growth.append((front, ms))
    table(itk, growth, BINS)
    print()
    table(itk, ls[len(growth):], LATE_BINS)


if __name__ == "__main__":
    main()
