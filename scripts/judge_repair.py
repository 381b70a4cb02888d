#!/usr/bin/python3
"""Judges a `liveset demo --brain --repair` folder against the truth, independently of liveset
(nibabel + numpy): per target the true GM voxels missing within R voxels before and after (closed
when at least halved), Dice before/after, and the share of added voxels that are GM.
Usage: scripts/judge_repair.py DIR [LABELS] [--radius 6]"""
import json, sys
import nibabel as nib
import numpy as np

def main():
    args = [a for a in sys.argv[1:] if not a.startswith('--')]
    d = args[0]
    labels = args[1] if len(args) > 1 else 'data/brainweb/labels_crisp.nii.gz'
    r = 6.0
    if '--radius' in sys.argv:
        r = float(sys.argv[sys.argv.index('--radius') + 1])
    gm = np.asarray(nib.load(labels).dataobj) == 2
    before = np.asarray(nib.load(f'{d}/seg.nii.gz').dataobj) != 0
    after = np.asarray(nib.load(f'{d}/seg_repaired.nii.gz').dataobj) != 0
    targets = json.load(open(f'{d}/report.json'))['targets']
    dice = lambda m: 2 * np.sum(m & gm) / (np.sum(m) + np.sum(gm))
    closed = 0
    rows = []
    for t in targets:
        i, j, k = t
        sl = tuple(slice(max(c - int(r), 0), c + int(r) + 1) for c in (i, j, k))
        grid = np.mgrid[sl]
        ball = ((grid[0] - i) ** 2 + (grid[1] - j) ** 2 + (grid[2] - k) ** 2) <= r * r
        mb = int(np.sum(gm[sl] & ~before[sl] & ball))
        ma = int(np.sum(gm[sl] & ~after[sl] & ball))
        ok = ma * 2 <= mb
        closed += ok
        rows.append((t, mb, ma, ok))
    added = after & ~before
    removed = before & ~after
    for t, mb, ma, ok in rows:
        print(f'  target {t}: missed GM within {r:g}: {mb} -> {ma} {"closed" if ok else "open"}')
    n = len(targets)
    print(f'closed {closed}/{n} = {closed / max(n, 1):.2f}; dice {dice(before):.4f} -> {dice(after):.4f}; '
          f'added {int(added.sum())} voxels, GM share {np.sum(added & gm) / max(added.sum(), 1):.3f}, '
          f'WM share {np.sum(added & (np.asarray(nib.load(labels).dataobj) == 3)) / max(added.sum(), 1):.3f}; removed {int(removed.sum())}')

main()
