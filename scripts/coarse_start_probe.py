#!/usr/bin/python3
"""A coarse-to-fine start measured by hand with today's binary (docs/BENCHMARKS.md, session 77).

Not a feature: a probe of what issue 16's "coarse-to-fine start" would give. It resamples IMAGE by
FACTOR (scipy.ndimage.zoom, order 1; the affine scaled about the first voxel's corner), segments the
coarse image from the given seeds (liveset's defaults otherwise), upsamples that mask onto IMAGE's
grid (trilinear at the fine voxel centres, > 0.5), and refines it on IMAGE with `--init-mask` and
the window the direct run chose (--mu-raw, --epsilon-raw, printed by `liveset segment`). Prints the
iterations and seconds of both runs and, with --labels (label 2 = grey matter), each mask's Dice.

Usage: scripts/coarse_start_probe.py BIN IMAGE MU_RAW EPSILON_RAW OUT_DIR [--factor 0.5]
           [--labels LABELS] [--threads 2] -- <liveset seed options, e.g. --seed-mm 35,83,113 ...>
"""
import argparse
import json
import os
import subprocess
import sys
import time

import nibabel as nib
import numpy as np
from scipy import ndimage


def run(cmd):
    start = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"coarse_start_probe: {' '.join(cmd)} failed: {r.stderr.strip()}")
    return time.monotonic() - start


def iterations(log):
    rows = [json.loads(line) for line in open(log) if '"iteration"' in line]
    return len(rows), sum(r["ms"] for r in rows) / 1000.0


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("bin")
    p.add_argument("image")
    p.add_argument("mu_raw")
    p.add_argument("epsilon_raw")
    p.add_argument("out")
    p.add_argument("--factor", type=float, default=0.5)
    p.add_argument("--labels")
    p.add_argument("--threads", default="2")
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    fine = nib.load(a.image)
    coarse_data = ndimage.zoom(np.asarray(fine.dataobj, dtype=np.float32), a.factor, order=1)
    aff = fine.affine.copy()
    aff[:3, :3] = fine.affine[:3, :3] / a.factor
    half = np.array([0.5, 0.5, 0.5])
    aff[:3, 3] = fine.affine[:3, 3] + fine.affine[:3, :3] @ half - aff[:3, :3] @ half
    coarse = os.path.join(a.out, "coarse.nii.gz")
    nib.save(nib.Nifti1Image(coarse_data, aff), coarse)

    coarse_mask, coarse_log = os.path.join(a.out, "coarse_mask.nii.gz"), os.path.join(a.out, "coarse.jsonl")
    wall_c = run([a.bin, "--threads", a.threads, "segment", coarse, *extra, "--out-mask", coarse_mask,
                  "--log", coarse_log, "--quiet"])
    c = nib.load(coarse_mask)
    to_coarse = np.linalg.inv(c.affine) @ fine.affine
    idx = np.indices(fine.shape[:3]).reshape(3, -1)
    at = to_coarse[:3, :3] @ idx + to_coarse[:3, 3:4]
    up = ndimage.map_coordinates(np.asarray(c.dataobj, dtype=np.float32), at, order=1, mode="nearest")
    up_mask = os.path.join(a.out, "upsampled.nii.gz")
    nib.save(nib.Nifti1Image((up.reshape(fine.shape[:3]) > 0.5).astype(np.uint8), fine.affine), up_mask)

    refined, refine_log = os.path.join(a.out, "refined.nii.gz"), os.path.join(a.out, "refine.jsonl")
    wall_r = run([a.bin, "--threads", a.threads, "segment", a.image, "--init-mask", up_mask, "--mu-raw", a.mu_raw,
                  "--epsilon-raw", a.epsilon_raw, "--out-mask", refined, "--log", refine_log, "--quiet"])
    its_c, s_c = iterations(coarse_log)
    its_r, s_r = iterations(refine_log)
    print(f"coarse  {coarse_data.shape}: {its_c} iterations, {s_c:.2f} s of iterations, {wall_c:.2f} s wall")
    print(f"refine  {fine.shape[:3]}: {its_r} iterations, {s_r:.2f} s of iterations, {wall_r:.2f} s wall")
    if a.labels:
        truth = np.asarray(nib.load(a.labels).dataobj) == 2
        for name, path in (("upsampled", up_mask), ("refined", refined)):
            m = np.asarray(nib.load(path).dataobj) > 0
            print(f"{name:9s} GM Dice {2 * (m & truth).sum() / (m.sum() + truth.sum()):.4f}")


if __name__ == "__main__":
    main()
