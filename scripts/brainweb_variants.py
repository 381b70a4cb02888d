#!/usr/bin/python3
# BrainWeb variants for the tissue-model window benchmark (docs/BENCHMARKS.md, "Window from the tissue
# model"): other units, contrast, noise, bias, skull-stripped, 2 mm. Float NIfTI with the labels' affine.
# Usage: /usr/bin/python3 scripts/brainweb_variants.py OUT_DIR   (Debian's python3-nibabel, python3-numpy)
import os, sys, zlib
import nibabel as nib
import numpy as np

here = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'data', 'brainweb')
out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-variants'
raw = open(os.path.join(here, 't1.mha'), 'rb').read()
start = raw.index(b'ElementDataFile = LOCAL\n') + len(b'ElementDataFile = LOCAL\n')
t1 = np.frombuffer(zlib.decompress(raw[start:]), dtype=np.uint8).reshape(180, 217, 181).transpose(2, 1, 0).astype(np.float32)
labels = nib.load(os.path.join(here, 'labels_crisp.nii.gz'))
mask = np.asarray(nib.load(os.path.join(here, 'brain_mask.nii.gz')).dataobj)
affine = labels.affine
rng = np.random.default_rng(7)
x, y, z = np.meshgrid(*[np.linspace(-1, 1, n) for n in t1.shape], indexing='ij')
field = np.exp(0.25 * (0.8 * x + 0.5 * y * y - 0.6 * z + 0.4 * x * z))  # smooth, about ±25 %
variants = {
    'orig': t1, 'scaled': t1 * 7.3 + 300, 'bias25': t1 * field,
    'noise': np.abs(t1 + rng.normal(0, 9, t1.shape)),
    'gamma07': 255 * (t1 / 255) ** 0.7, 'gamma14': 255 * (t1 / 255) ** 1.4,
    'stripped': t1 * (mask > 0), 'biasnoise': np.abs(t1 * field + rng.normal(0, 6, t1.shape)),
}
os.makedirs(out, exist_ok=True)
for name, a in variants.items():
    nib.save(nib.Nifti1Image(a.astype(np.float32), affine), os.path.join(out, name + '.nii.gz'))
nib.save(nib.Nifti1Image(np.asarray(labels.dataobj).astype(np.uint8), affine), os.path.join(out, 'labels.nii.gz'))
nib.save(nib.Nifti1Image(mask.astype(np.uint8), affine), os.path.join(out, 'mask.nii.gz'))
print('wrote', ', '.join(sorted(variants)), 'to', out)
