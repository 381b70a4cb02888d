#!/usr/bin/python3
# BrainWeb with enlarged ventricles (atrophy, hydrocephalus; docs/BENCHMARKS.md, session 69): white
# matter within D = 4..12 mm of the ventricles (CSF over 20 mm inside the brain mask, opened once)
# becomes CSF, its intensity drawn from the T1's own ventricle voxels. Writes
# OUT/vent{D}/{t1,labels,mask}.nii.gz (labels: that white matter relabelled CSF).
# Usage: /usr/bin/python3 scripts/brainweb_ventricle_variants.py OUT_DIR  (python3-nibabel, python3-scipy)
import os, sys, numpy as np, nibabel as nib
from scipy import ndimage as ndi
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data
out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-ventricle-variants'
t1, L, M, affine = brainweb_data.load()
M = M > 0
depth = ndi.distance_transform_edt(M)
vent = (L == 1) & (depth > 20)
vent = ndi.binary_opening(vent, iterations=1)
print('ventricle voxels', vent.sum(), 'csf mean', t1[vent].mean(), t1[vent].std())
rng = np.random.default_rng(11)
vals = t1[vent]
for d in (4, 5, 6, 7, 8, 10, 12):
    grow = ndi.distance_transform_edt(~vent) <= d
    new = grow & (L == 3)
    t = t1.copy(); l = L.copy()
    t[new] = rng.choice(vals, new.sum()); l[new] = 1
    o = os.path.join(out, 'vent%d' % d); os.makedirs(o, exist_ok=True)
    nib.save(nib.Nifti1Image(t, affine), os.path.join(o, 't1.nii.gz'))
    nib.save(nib.Nifti1Image(l, affine), os.path.join(o, 'labels.nii.gz'))
    nib.save(nib.Nifti1Image(M.astype(np.uint8), affine), os.path.join(o, 'mask.nii.gz'))
    print('vent%d: %d WM voxels -> CSF (%.0f ml), WM left %d' % (d, new.sum(), new.sum() / 1000, (l == 3).sum()))
