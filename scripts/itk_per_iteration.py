#!/usr/bin/python3
"""Per-iteration time of liveset's step against ITK's threshold level set at equal front size.

Bins each iteration by the front it started from (ITK: the active layer after the previous
iteration; liveset: the zero layer after the previous iteration) and prints the median ms per
iteration of both programs per bin and their ratio. The first table uses liveset's growth phase
only (before its zero layer first passes 150 000 points); the second, the fronts above that, where
liveset's run goes on into convergence and lets still stretches sleep (ITK's front grows more
slowly: about 800 iterations to 200 000 points, 1 100 to 250 000, so run it with --iterations 1700).
A bin one program never reached says so.

Given several rounds (pairs of logs, each pair run back to back), each bin also shows every
round's ratio and their median: on a noisy machine one pair can be off by 2x either way.

Usage: scripts/itk_per_iteration.py ITK_LOG LIVESET_LOG [ITK_LOG LIVESET_LOG ...]   (JSON lines, from --log)
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


def split_growth(ls):
    """liveset's iterations up to its zero layer first passing the last growth bin, and the rest."""
    top = BINS[-1][1]
    for n, (front, _) in enumerate(ls):
        if front > top:
            return ls[:n], ls[n:]
    return ls, []


def medians(rows, lo, hi):
    ms = [m for f, m in rows if lo <= f < hi]
    return statistics.median(ms) if ms else None


def table(rounds, bins):
    """rounds: [(itk rows, liveset rows)] for one table's part of each liveset run."""
    several = len(rounds) > 1
    head = "| front size | ITK ms | liveset ms | ITK / liveset |"
    print(head + (" per round |" if several else ""))
    print("|---|--:|--:|--:|" + ("---|" if several else ""))
    for lo, hi in bins:
        per_round = []
        for itk, ls in rounds:
            a, b = medians(itk, lo, hi), medians(ls, lo, hi)
            if a is not None and b is not None:
                per_round.append((a, b))
        if not per_round:
            n_itk = sum(1 for itk, _ in rounds for f, _ in itk if lo <= f < hi)
            n_ls = sum(1 for _, ls in rounds for f, _ in ls if lo <= f < hi)
            print(f"| {lo}-{hi} | {n_itk} ITK / {n_ls} liveset iterations | | |" + (" |" if several else ""))
            continue
        ratios = [a / b for a, b in per_round]
        ma = statistics.median(a for a, _ in per_round)
        mb = statistics.median(b for _, b in per_round)
        line = f"| {lo}-{hi} | {ma:.2f} | {mb:.2f} | {statistics.median(ratios):.1f}x |"
        if several:
            line += " " + " / ".join(f"{r:.1f}x" for r in ratios) + " |"
        print(line)


def main():
    args = sys.argv[1:]
    if not args or len(args) % 2:
        sys.exit(__doc__.strip().splitlines()[-1])
    growth, late = [], []
    for itk_path, ls_path in zip(args[0::2], args[1::2]):
        itk = read(itk_path, "active_layer")
        g, rest = split_growth(read(ls_path, "zero_layer"))
        growth.append((itk, g))
        late.append((itk, rest))
    table(growth, BINS)
    print()
    table(late, LATE_BINS)


if __name__ == "__main__":
    main()
