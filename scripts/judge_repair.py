#!/usr/bin/python3
"""Judges a `liveset demo --brain --repair` folder against the truth, independently of liveset
(nibabel + numpy): per target the true GM voxels missing within R voxels before and after (closed
when at least halved), Dice before/after, and the share of added voxels that are GM. When the labels
lie on another grid than the segmentation (another storage order, e.g. a MINC input), they are carried
onto the segmentation's grid by the two files' affines (nearest voxel; the grids must coincide).
Usage: scripts/judge_repair.py DIR [LABELS] [--radius 6]"""
import json, sys
import nibabel as nib
import numpy as np

def on_grid(labels, seg):
    """The labels on the segmentation's voxel grid: voxel n of seg holds the label at the same physical
    point (nearest voxel); fails when the grids do not coincide."""
    a = np.asarray(labels.dataobj)
    if a.shape == seg.shape and np.allclose(labels.affine, seg.affine, atol=1e-3):
        return a
    m = np.linalg.inv(labels.affine) @ seg.affine  # seg voxel -> label voxel
    idx = np.indices(seg.shape).reshape(3, -1)
    q = m[:3, :3] @ idx + m[:3, 3:4]
    r = np.rint(q).astype(int)
    if np.abs(q - r).max() > 1e-2 or (r < 0).any() or (r >= np.array(a.shape)[:, None]).any():
        sys.exit('judge_repair: the labels do not lie on the segmentation\'s grid')
    return a[r[0], r[1], r[2]].reshape(seg.shape)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith('--')]
    d = args[0]
    labels = args[1] if len(args) > 1 else 'data/brainweb/labels_crisp.nii.gz'
    r = 6.0
    if '--radius' in sys.argv:
        r = float(sys.argv[sys.argv.index('--radius') + 1])
    seg = nib.load(f'{d}/seg.nii.gz')
    lab = on_grid(nib.load(labels), seg)
    gm = lab == 2
    before = np.asarray(seg.dataobj) != 0
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
          f'WM share {np.sum(added & (lab == 3)) / max(added.sum(), 1):.3f}; removed {int(removed.sum())}')

main()
