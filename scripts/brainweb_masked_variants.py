#!/usr/bin/python3
# BrainWeb as masking and normalising tools store it (docs/BENCHMARKS.md, session 62): NaN outside the
# brain (SPM's masked images, fslmaths -nan), raw and z-scored, stray NaN in a head, air set NaN by a
# threshold, and the same brain with 0 outside; FreeSurfer-normalised T1s (T1.mgz-like: white matter
# scaled to 110, the voxels labelled white matter within ±PIN of 110 set to exactly 110, uint8, conformed LIA axes; as .mgz and
# .nii.gz), without the pin, with Rician noise before the pin, and stripped (brainmask.mgz-like).
# Each in OUT/NAME/{t1,labels,mask}.nii.gz (and t1/labels/mask.mgz for fsT1mgz).
# Usage: /usr/bin/python3 scripts/brainweb_masked_variants.py OUT_DIR  (Debian's python3-nibabel)
import os, sys
import nibabel as nib, numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-masked-variants'
t1, labels, mask, base = brainweb_data.load()
rng = np.random.default_rng(62)
def rician(a, s): return np.sqrt((a + rng.normal(0, s, a.shape))**2 + rng.normal(0, s, a.shape)**2)
def save(name, T, dtype=np.float32, lia=False, mgz=False):
    d = os.path.join(out, name); os.makedirs(d, exist_ok=True)
    arrays, aff = [T.astype(dtype), labels.astype(np.uint8), mask.astype(np.uint8)], base
    if lia:  # FreeSurfer's conformed axes: LPS -> LIA
        t = nib.orientations.ornt_transform(nib.orientations.io_orientation(base), nib.orientations.axcodes2ornt(('L', 'I', 'A')))
        aff = base @ nib.orientations.inv_ornt_aff(t, T.shape)
        arrays = [nib.orientations.apply_orientation(a, t).astype(a.dtype) for a in arrays]
    for a, f in zip(arrays, ('t1', 'labels', 'mask')):
        nib.save(nib.Nifti1Image(a, aff), os.path.join(d, f + '.nii.gz'))
        if mgz: nib.save(nib.MGHImage(a, aff), os.path.join(d, f + '.mgz'))
    print(name, arrays[0].shape, arrays[0].dtype, flush=True)
def freesurfer(T, pin=12.0):
    S = np.clip(np.round(T * (110.0 / T[labels == 3].mean())), 0, 255)
    if pin > 0: S[(labels == 3) & (np.abs(S - 110) <= pin)] = 110  # mri_normalize pins the voxels it takes for white matter
    return S

T = rician(t1, 7)
S = T.copy(); S[mask == 0] = np.nan; save('strippednan', S)
b = T[mask > 0]; Z = (T - b.mean()) / b.std(); Z[mask == 0] = np.nan; save('strippednanz', Z)
H = T.copy(); H.flat[rng.choice(H.size, 50, replace=False)] = np.nan; save('headnan50', H)
C = T.copy(); C[T < 15] = np.nan; save('headnanair', C)
Zr = T.copy(); Zr[mask == 0] = 0; save('strippedzero', Zr)
save('fsT1', freesurfer(t1), np.uint8, lia=True)
save('fsT1mgz', freesurfer(t1), np.uint8, lia=True, mgz=True)
save('fsT1nospike', freesurfer(t1, 0), np.uint8, lia=True)
save('fs_ric5', freesurfer(rician(t1, 5)), np.uint8)
save('fs_ric9', freesurfer(rician(t1, 9)), np.uint8)
save('fs_ric9_pin6', freesurfer(rician(t1, 9), 6), np.uint8)
B = freesurfer(rician(t1, 5)); B[mask == 0] = 0; save('fs_brainmask_ric5', B, np.uint8)
