#!/usr/bin/python3
"""Recall and precision of `liveset holes --out-mask` against the truth's perforations, computed
independently of liveset (nibabel + scipy). A truth perforation: a 6-connected region of missed
truth (truth and not seg) touching, through voxels outside the seg and the truth, both the inner
label and the rest (as liveset eval --inner-label). Recall: perforations of >= MIN voxels holding a
finder voxel. Precision: finder candidates (6-connected components of the finder mask) holding a
missed-truth voxel; by voxel: finder voxels that are missed truth.
Usage: scripts/finder_recall.py SEG FINDER_MASK LABELS [--label 2] [--inner 3] [--min 50]"""
import sys
import nibabel as nib
import numpy as np
from scipy import ndimage

def opt(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default

seg_p, found_p, labels_p = sys.argv[1:4]
label, inner_label, min_voxels = opt('--label', 2), opt('--inner', 3), opt('--min', 50)
lab = np.asarray(nib.load(labels_p).dataobj)
seg = np.asarray(nib.load(seg_p).dataobj) != 0
found = np.asarray(nib.load(found_p).dataobj) != 0
truth = lab == label
inner = (lab == inner_label) & ~seg & ~truth
outer = ~seg & ~truth & ~inner
missed = truth & ~seg
six = ndimage.generate_binary_structure(3, 1)
comp, n = ndimage.label(missed, six)
def touching(mask):  # labels of missed regions with a face neighbour in mask (or the border for outer)
    grown = ndimage.binary_dilation(mask, six)
    return set(np.unique(comp[grown & missed])) - {0}
ti, to = touching(inner), touching(outer)
border = np.zeros_like(missed)
border[[0, -1], :, :] = border[:, [0, -1], :] = border[:, :, [0, -1]] = True
to |= set(np.unique(comp[border & missed])) - {0}
sizes = np.bincount(comp.ravel())
perf = [k for k in (ti & to) if sizes[k] >= min_voxels]
hit = set(np.unique(comp[found])) - {0}
recall = sum(k in hit for k in perf) / max(len(perf), 1)
fcomp, fn = ndimage.label(found, six)
good = set(np.unique(fcomp[missed & found])) - {0}
print(f'truth perforations >= {min_voxels}: {len(perf)}, met by the finder: {sum(k in hit for k in perf)} (recall {recall:.3f}); '
      f'finder candidates {fn}, holding missed truth {len(good)} (precision {len(good) / max(fn, 1):.3f}); '
      f'finder voxels {int(found.sum())}, missed truth among them {int((found & missed).sum())} '
      f'({(found & missed).sum() / max(found.sum(), 1):.3f})')
