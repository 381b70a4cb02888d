#!/usr/bin/env python3
"""Times Python's Session stepping one step at a time until it converges, as the viewer's Run
does (docs/BENCHMARKS.md, session 81): total seconds, steps of each kind, the slowest step.

    PYTHONPATH=build/python python3 scripts/session_timing.py IMAGE --coarse-start auto \\
        --seed 50,119,161 --seed 50,179,54 ...        # voxel indices, radius 2 (or I,J,K:R)
"""
import argparse
import time

import liveset


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("image")
    ap.add_argument("--seed", action="append", required=True, help="I,J,K[:R] in voxels; repeatable")
    ap.add_argument("--coarse-start", default="auto", choices=["auto", "on", "off"])
    ap.add_argument("--max-steps", type=int, default=5000)
    a = ap.parse_args()
    t0 = time.time()
    s = liveset.Session(liveset.read(a.image), coarse_start=a.coarse_start)
    print(f"prepared in {time.time() - t0:.2f} s")
    for text in a.seed:
        ijk, _, r = text.partition(":")
        s.add_seed(tuple(float(v) for v in ijk.split(",")), float(r) if r else 2.0)
    t0, worst, n, st = time.time(), (0.0, 0, False), 0, {}
    while n < a.max_steps:
        t = time.time()
        st = s.step(1)
        n += 1
        if time.time() - t > worst[0]:
            worst = (time.time() - t, n, st["coarse"])
        if st["converged"] or st["vanished"]:
            break
    print(f"run {time.time() - t0:.2f} s, {n} steps ({st['coarse_iterations']} coarse, {st['iterations']} fine), "
          f"converged {st['converged']}; slowest step {worst[0]:.3f} s (step {worst[1]}, coarse {worst[2]})")


if __name__ == "__main__":
    main()
