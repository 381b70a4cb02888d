#!/usr/bin/python3
# BrainWeb aged (docs/BENCHMARKS.md, session 70): cortical atrophy — grey matter within K = 1..2 voxels
# of the sulcal CSF (CSF under 20 mm deep in the brain mask) becomes CSF — with the ventricles
# grown by 6 mm into white matter as in brainweb_ventricle_variants.py; the intensities drawn from
# the T1's own CSF voxels. Writes OUT/atrophy{K}/{t1,labels,mask}.nii.gz (labels: relabelled CSF).
# Usage: /usr/bin/python3 scripts/brainweb_atrophy_variants.py OUT_DIR  (python3-nibabel, python3-scipy)
import os, sys, numpy as np, nibabel as nib
from scipy import ndimage as ndi
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data
out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-atrophy-variants'
t1, L, M, affine = brainweb_data.load()
M = M > 0
depth = ndi.distance_transform_edt(M)
vent = ndi.binary_opening((L == 1) & (depth > 20), iterations=1)
sulcal = (L == 1) & (depth <= 20)
rng = np.random.default_rng(13)
csf_vals = t1[L == 1]
vent_vals = t1[vent]
grown = (ndi.distance_transform_edt(~vent) <= 6) & (L == 3)
for k in (1, 2):
    thin = (ndi.distance_transform_edt(~sulcal) <= k) & (L == 2)
    t = t1.copy(); l = L.copy()
    t[grown] = rng.choice(vent_vals, grown.sum()); l[grown] = 1
    t[thin] = rng.choice(csf_vals, thin.sum()); l[thin] = 1
    o = os.path.join(out, 'atrophy%d' % k); os.makedirs(o, exist_ok=True)
    nib.save(nib.Nifti1Image(t, affine), os.path.join(o, 't1.nii.gz'))
    nib.save(nib.Nifti1Image(l, affine), os.path.join(o, 'labels.nii.gz'))
    nib.save(nib.Nifti1Image(M.astype(np.uint8), affine), os.path.join(o, 'mask.nii.gz'))
    print('atrophy%d: %d GM voxels -> CSF (%.0f ml), %d WM -> CSF (%.0f ml), GM left %d' %
          (k, thin.sum(), thin.sum() / 1000, grown.sum(), grown.sum() / 1000, (l == 2).sum()))
