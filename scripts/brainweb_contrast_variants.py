#!/usr/bin/python3
# BrainWeb's labels in T2, PD and FLAIR contrast (docs/BENCHMARKS.md, session 63): each label's value (T2: CSF
# 250, GM 110, WM 75, fat 150, muscle 45, skin 80, skull 8, glial matter 140, connective tissue 100;
# PD: CSF 200, GM 170, WM 140, fat 170, muscle 100, skin 120, skull 25, glial 170, connective 120;
# session 64's FLAIR, CSF dark and grey matter above white: CSF 25, GM 120, WM 95, fat 130, muscle 50,
# skin 100, skull 8, glial matter 150, connective tissue 90),
# blurred by a Gaussian of 0.7 voxel, Gaussian noise σ 4 taken as magnitude; the T1's lattice. Each
# in OUT/NAME/{t1,labels,mask}.nii.gz ("t1" is the file name variant_dice.sh reads).
# Usage: /usr/bin/python3 scripts/brainweb_contrast_variants.py OUT_DIR  (Debian's python3-nibabel, python3-scipy)
import os, sys
import nibabel as nib, numpy as np
from scipy.ndimage import gaussian_filter
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-contrast-variants'
t1, labels, mask, base = brainweb_data.load()
rng = np.random.default_rng(63)
values = {'t2': [0, 250, 110, 75, 150, 45, 80, 8, 140, 100], 'pd': [0, 200, 170, 140, 170, 100, 120, 25, 170, 120],
          'flair': [0, 25, 120, 95, 130, 50, 100, 8, 150, 90]}
for name, v in values.items():
    T = gaussian_filter(np.asarray(v, np.float64)[np.minimum(labels, 9)], 0.7)
    T = np.abs(T + rng.normal(0, 4, T.shape)).astype(np.float32)
    d = os.path.join(out, name); os.makedirs(d, exist_ok=True)
    for a, f in ((T, 't1'), (labels.astype(np.uint8), 'labels'), (mask.astype(np.uint8), 'mask')):
        nib.save(nib.Nifti1Image(a, base), os.path.join(d, f + '.nii.gz'))
    print(name, T.shape, flush=True)
