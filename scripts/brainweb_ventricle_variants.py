#!/usr/bin/python3
# BrainWeb with enlarged ventricles (atrophy, hydrocephalus; docs/BENCHMARKS.md, session 69): white
# matter within D = 4..12 mm of the ventricles (CSF over 20 mm inside the brain mask, opened once)
# becomes CSF, its intensity drawn from the T1's own ventricle voxels. Writes
# OUT/vent{D}/{t1,labels,mask}.nii.gz (labels: that white matter relabelled CSF).
# Usage: /usr/bin/python3 scripts/brainweb_ventricle_variants.py OUT_DIR  (python3-nibabel, python3-scipy)
import os, sys, zlib, numpy as np, nibabel as nib
from scipy import ndimage as ndi
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'data', 'brainweb')
out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-ventricle-variants'
raw = open(os.path.join(here, 't1.mha'), 'rb').read()
start = raw.index(b'ElementDataFile = LOCAL\n') + len(b'ElementDataFile = LOCAL\n')
t1 = np.frombuffer(zlib.decompress(raw[start:]), dtype=np.uint8).reshape(180, 217, 181).transpose(2, 1, 0).astype(np.float32)
lab = nib.load(os.path.join(here, 'labels_crisp.nii.gz')); L = np.asarray(lab.dataobj).astype(np.uint8)
M = np.asarray(nib.load(os.path.join(here, 'brain_mask.nii.gz')).dataobj) > 0
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
    nib.save(nib.Nifti1Image(t, lab.affine), os.path.join(o, 't1.nii.gz'))
    nib.save(nib.Nifti1Image(l, lab.affine), os.path.join(o, 'labels.nii.gz'))
    nib.save(nib.Nifti1Image(M.astype(np.uint8), lab.affine), os.path.join(o, 'mask.nii.gz'))
    print('vent%d: %d WM voxels -> CSF (%.0f ml), WM left %d' % (d, new.sum(), new.sum() / 1000, (l == 3).sum()))
