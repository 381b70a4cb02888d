#!/usr/bin/python3
# BrainWeb on other grids, for the held-out-style checks of the truth-free repair (scripts/fig5_cli.sh):
# 1.2 mm isotropic (NIfTI), 1 x 1 x 1.5 mm stored with the first axis flipped (NIfTI), and 1 mm stored
# sagittally as MINC (rawtominc). T1 trilinear, labels and brain mask nearest; every file keeps BrainWeb's
# physical space, so the demo's seeds given in mm (LPS = BrainWeb's voxel index) stay valid.
# Usage: /usr/bin/python3 scripts/brainweb_geometry.py OUT_DIR   (nibabel, numpy, scipy; minc-tools' rawtominc)
import os, subprocess, sys
import nibabel as nib
import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-geometry'
t1, labels, mask, base = brainweb_data.load()  # base: RAS diag(-1, -1, 1), origin 0


def resample(a, new_index_to_old, shape, order):
    """Samples `a` (BrainWeb's grid) at old = M @ new + t for every new voxel index."""
    m, t = new_index_to_old
    return ndimage.affine_transform(a, m, offset=t, output_shape=shape, order=order, mode='constant', cval=0)


def write(name, m, t, shape, minc=False):
    """A variant whose voxel n lies at BrainWeb's voxel m @ n + t (so its affine is base @ [m t])."""
    d = os.path.join(out, name)
    os.makedirs(d, exist_ok=True)
    aff = base @ np.block([[m, t[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
    imgs = {'t1': resample(t1, (m, t), shape, 1).astype(np.float32),
            'labels': resample(labels, (m, t), shape, 0).astype(np.uint8),
            'mask': resample(mask, (m, t), shape, 0).astype(np.uint8)}
    for k, a in imgs.items():
        nib.save(nib.Nifti1Image(a, aff), os.path.join(d, k + '.nii.gz'))
    if minc:  # T1 and brain mask as MINC (minc-tools' rawtominc, sagittal storage: x slowest, then z, y; x
        # stored left to right with a positive step, y with a negative one); the labels stay NIfTI, which
        # scripts/judge_repair.py maps onto the segmentation's grid by the affines. (nii2mnc is not used:
        # given this permuted sform it writes x's start 180 mm off.)
        for k, kind in (('t1', '-float'), ('mask', '-byte')):
            a = {'t1': t1, 'mask': mask}[k]  # BrainWeb's grid: RAS = (-i, -j, k)
            data = np.ascontiguousarray(a[::-1].transpose(0, 2, 1)).astype(np.float32 if k == 't1' else np.uint8)
            mnc = os.path.join(d, k + '.mnc')
            if os.path.exists(mnc):
                os.remove(mnc)
            subprocess.run(['rawtominc', '-sagittal', kind, '-clobber', '-xstart', str(-(a.shape[0] - 1)), '-xstep', '1',
                            '-ystart', '0', '-ystep', '-1', '-zstart', '0', '-zstep', '1'] + (['-scan_range'] if k == 't1' else []) +
                           [mnc, str(a.shape[0]), str(a.shape[2]), str(a.shape[1])], input=data.tobytes(), check=True)
            os.remove(os.path.join(d, k + '.nii.gz'))

n = np.array(t1.shape, dtype=float)
write('iso12', np.diag([1.2, 1.2, 1.2]), np.zeros(3), tuple(int(v) for v in np.floor((n - 1) / 1.2) + 1))
flip = np.diag([-1.0, 1.0, 1.5])  # first axis stored right to left, 1.5 mm slices
write('aniso15_flip', flip, np.array([n[0] - 1, 0, 0]), (int(n[0]), int(n[1]), int((n[2] - 1) // 1.5) + 1))
write('sagittal_minc', np.eye(3), np.zeros(3), t1.shape, minc=True)  # labels on BrainWeb's grid; T1 and mask re-stored
print('wrote iso12, aniso15_flip, sagittal_minc to', out)
