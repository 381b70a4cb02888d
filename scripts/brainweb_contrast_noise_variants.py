#!/usr/bin/python3
# BrainWeb's labels as a PD or T2 (scripts/brainweb_contrast_variants.py's values) under what real scans
# add (docs/BENCHMARKS.md, session 66): Rician noise (pd_ric9, t2_ric9), a linear shading of ±15 %
# (pd_bias15, t2_bias15), a lower grey-white contrast (pd_lowc: CSF 185, GM 162, WM 145; pd_ric6_lowc
# with Rician σ 6), a brighter skull and muscle (pd_skull60), and an affine intensity scaling
# (pd_scaled: ×23.7 + 300); since session 67 T2s with fat as bright as CSF (t2_fat220, and under Rician
# σ 6), Rician σ 5, a lower contrast (CSF 200, GM 100, WM 80), other units and a brighter skull.
# Blurred by a Gaussian of 0.7 voxel; noise σ 4 as magnitude unless Rician.
# Each in OUT/NAME/{t1,labels,mask}.nii.gz ("t1" is the file name variant_dice.sh reads).
# Usage: /usr/bin/python3 scripts/brainweb_contrast_noise_variants.py OUT_DIR  (python3-nibabel, python3-scipy)
import os, sys
import nibabel as nib, numpy as np
from scipy.ndimage import gaussian_filter
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-contrast-noise-variants'
t1, labels, mask, base = brainweb_data.load()
rng = np.random.default_rng(66)
pd = [0, 200, 170, 140, 170, 100, 120, 25, 170, 120]
t2 = [0, 250, 110, 75, 150, 45, 80, 8, 140, 100]
pd_lowc = [0, 185, 162, 145, 165, 100, 120, 25, 165, 120]
t2_fat = [0, 250, 110, 75, 220, 45, 80, 8, 140, 100]
t2_lowc = [0, 200, 100, 80, 150, 45, 80, 8, 130, 100]


def make(v, sigma=4, rician=False, bias=0.0):
    T = gaussian_filter(np.asarray(v, np.float64)[np.minimum(labels, 9)], 0.7)
    if bias:
        y = np.linspace(-1, 1, T.shape[1])[None, :, None]
        z = np.linspace(-1, 1, T.shape[2])[None, None, :]
        T = T * (1 + bias * (0.7 * y + 0.3 * z))
    if rician:
        T = np.hypot(T + rng.normal(0, sigma, T.shape), rng.normal(0, sigma, T.shape))
    else:
        T = np.abs(T + rng.normal(0, sigma, T.shape))
    return T.astype(np.float32)


variants = [('pd_ric9', lambda: make(pd, 9, True)), ('pd_bias15', lambda: make(pd, 4, False, 0.15)),
            ('pd_lowc', lambda: make(pd_lowc)), ('pd_skull60', lambda: make([0, 200, 170, 140, 170, 120, 130, 60, 170, 120])),
            ('pd_ric6_lowc', lambda: make(pd_lowc, 6, True)), ('t2_ric9', lambda: make(t2, 9, True)),
            ('t2_bias15', lambda: make(t2, 4, False, 0.15)), ('pd_scaled', lambda: make(pd) * 23.7 + 300),
            # session 67: T2s as other sequences and scanners give them: fat as bright as CSF (fast spin
            # echo), Rician σ 5, a lower contrast, other units, a brighter skull and muscle
            ('t2_fat220', lambda: make(t2_fat)), ('t2_ric5', lambda: make(t2, 5, True)), ('t2_lowc', lambda: make(t2_lowc)),
            ('t2_scaled', lambda: make(t2) * 11.3 + 50), ('t2_skull40', lambda: make([0, 250, 110, 75, 150, 70, 90, 40, 140, 100])),
            ('t2_fat220_ric6', lambda: make(t2_fat, 6, True))]
for name, build in variants:  # in this order: each draws its noise from the one generator
    T = build()
    d = os.path.join(out, name)
    os.makedirs(d, exist_ok=True)
    for a, f in ((T, 't1'), (labels.astype(np.uint8), 'labels'), (mask.astype(np.uint8), 'mask')):
        nib.save(nib.Nifti1Image(a, base), os.path.join(d, f + '.nii.gz'))
    print(name, flush=True)
