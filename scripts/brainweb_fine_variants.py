#!/usr/bin/python3
# Finely sampled BrainWeb variants for the coarse start (docs/BENCHMARKS.md, session 78): a variant
# folder (t1, labels, mask .nii.gz, 1 mm) resampled onto a finer grid as brainweb_slab_variants.py makes
# hr07r (trilinear T1, nearest labels and mask, the affine scaled about the first voxel), with Rician
# noise of sigma SIGMA; optionally skull-stripped (T1 times the mask) or scaled.
# Usage: /usr/bin/python3 scripts/brainweb_fine_variants.py SRC_DIR|brainweb OUT_DIR SPACING [SIGMA=6]
#            [--stripped] [--scale F] [--seed N]   (Debian's python3-nibabel, python3-scipy)
import argparse, os, sys
import nibabel as nib, numpy as np
from scipy import ndimage
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

p = argparse.ArgumentParser()
p.add_argument('src'); p.add_argument('out'); p.add_argument('spacing', type=float); p.add_argument('sigma', type=float, nargs='?', default=6.0)
p.add_argument('--stripped', action='store_true'); p.add_argument('--scale', type=float, default=1.0); p.add_argument('--seed', type=int, default=78)
a = p.parse_args()
if a.src == 'brainweb':
    t1, labels, mask, base = brainweb_data.load()
else:
    load = lambda n: nib.load(os.path.join(a.src, n + '.nii.gz'))
    t1, labels, mask, base = np.asarray(load('t1').dataobj, np.float32), np.asarray(load('labels').dataobj), np.asarray(load('mask').dataobj), load('t1').affine
h = np.full(3, a.spacing); m = np.diag(h)
shape = tuple(int(v) for v in np.floor((np.array(t1.shape, float) - 1) / h) + 1)
aff = base @ np.block([[m, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]])
r = lambda x, o: ndimage.affine_transform(x, m, output_shape=shape, order=o)
T, L, M = r(t1, 1), r(labels, 0), r(mask, 0)
rng = np.random.default_rng(a.seed)
if a.sigma > 0: T = np.sqrt((T + rng.normal(0, a.sigma, T.shape))**2 + rng.normal(0, a.sigma, T.shape)**2)
if a.stripped: T = T * (M > 0)
T = T * a.scale
os.makedirs(a.out, exist_ok=True)
nib.save(nib.Nifti1Image(T.astype(np.float32), aff), os.path.join(a.out, 't1.nii.gz'))
nib.save(nib.Nifti1Image(L.astype(np.uint8), aff), os.path.join(a.out, 'labels.nii.gz'))
nib.save(nib.Nifti1Image(M.astype(np.uint8), aff), os.path.join(a.out, 'mask.nii.gz'))
print(a.out, T.shape)
