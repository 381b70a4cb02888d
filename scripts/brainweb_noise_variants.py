#!/usr/bin/python3
# BrainWeb variants for the pre-smoothing (docs/BENCHMARKS.md, session 54): Rician noise, other grids,
# other units, skull-stripped + noise; and for the head threshold under noise (session 55): heavier,
# correlated and multi-channel noise, cropped fields of view. Each in OUT/NAME/{t1,labels,mask}.nii.gz.
# Usage: /usr/bin/python3 scripts/brainweb_noise_variants.py OUT_DIR  (Debian's python3-nibabel, -scipy)
import os, sys
import nibabel as nib, numpy as np
from scipy import ndimage
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-noise-variants'
t1, labels, mask, base = brainweb_data.load()
n = np.array(t1.shape, float)
rng = np.random.default_rng(54)
def rician(a, s): return np.sqrt((a + rng.normal(0, s, a.shape))**2 + rng.normal(0, s, a.shape)**2)
def save(name, T, L, M, aff):
    d = os.path.join(out, name); os.makedirs(d, exist_ok=True)
    nib.save(nib.Nifti1Image(T.astype(np.float32), aff), os.path.join(d, 't1.nii.gz'))
    nib.save(nib.Nifti1Image(L.astype(np.uint8), aff), os.path.join(d, 'labels.nii.gz'))
    nib.save(nib.Nifti1Image(M.astype(np.uint8), aff), os.path.join(d, 'mask.nii.gz'))
    print(name, T.shape, flush=True)
def res(h):
    h = np.array(h, float); m = np.diag(h)
    shape = tuple(int(v) for v in np.floor((n - 1) / h) + 1)
    aff = base @ np.block([[m, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]])
    r = lambda a, o: ndimage.affine_transform(a, m, output_shape=shape, order=o)
    return r(t1, 1), r(labels, 0), r(mask, 0), aff
save('ric5', rician(t1, 5), labels, mask, base)
save('ric9', rician(t1, 9), labels, mask, base)
save('ric14', rician(t1, 14), labels, mask, base)
save('scaledn', rician(t1, 9) * 7.3 + 300, labels, mask, base)
save('strippedn', rician(t1 * (mask > 0), 9) * (mask > 0), labels, mask, base)
T, L, M, a = res([1.3, 1.3, 1.3]); save('iso13r', rician(T, 8), L, M, a)
T, L, M, a = res([0.9, 0.9, 2.0]); save('z2r', rician(T, 7), L, M, a)
T, L, M, a = res([1.6, 1.6, 1.6]); save('iso16r', rician(T, 6), L, M, a)
# Session 55 (the head threshold under noise): a cropped field of view with little air left, clean and
# noisy; a 4-channel sum-of-squares background (non-central chi: mode √7 σ above 0, not at the floor);
# heavier Rician noise.
def crop(a, lo, hi): return a[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
ix = np.argwhere(ndimage.binary_opening(t1 > 20, iterations=2))
lo = ix.min(0) + np.array([12, 12, 40]); hi = ix.max(0) + 1 - np.array([12, 12, 0])
ca = base @ np.block([[np.eye(3), lo.reshape(3, 1).astype(float)], [np.zeros((1, 3)), np.ones((1, 1))]])
C = [crop(a, lo, hi) for a in (t1, labels, mask)]
save('crop', C[0], C[1], C[2], ca)
save('cropn', rician(C[0], 9), C[1], C[2], ca)
def coils(a, s, k): return np.sqrt(sum((a / np.sqrt(k) + rng.normal(0, s, a.shape))**2 + rng.normal(0, s, a.shape)**2 for _ in range(k)))
save('coil4', coils(t1, 5, 4), labels, mask, base)
save('ric18', rician(t1, 18), labels, mask, base)
# Noise correlated over ~a voxel (as after k-space zero-filling) and a deeper crop (14 % air left).
rng = np.random.default_rng(55)
def correlated(shape, s, r):
    g = ndimage.gaussian_filter(rng.normal(0, 1, shape), r); return g / g.std() * s
for s, r in ((14, 0.7), (14, 1.0), (9, 1.0)):
    save('ric%dc%g' % (s, r), np.sqrt((t1 + correlated(t1.shape, s, r))**2 + correlated(t1.shape, s, r)**2), labels, mask, base)
lo = ix.min(0) + np.array([28, 30, 60]); hi = ix.max(0) + 1 - np.array([28, 30, 10])
ca = base @ np.block([[np.eye(3), lo.reshape(3, 1).astype(float)], [np.zeros((1, 3)), np.ones((1, 1))]])
C = [crop(a, lo, hi) for a in (t1, labels, mask)]
save('deepcrop', C[0], C[1], C[2], ca)
save('deepcropn', rician(C[0], 9), C[1], C[2], ca)
save('deepcropn14', rician(C[0], 14), C[1], C[2], ca)
