#!/bin/bash
# How far the front carries into thin structures (docs/BENCHMARKS.md, sessions 70-71): a 7-voxel cube
# seeded, joined to a 52-voxel tube (W×W voxels) or sheet (16×W voxels) of the same intensity
# (100, noise σ 2, background 0), window 100 ± 30, α 0, no ROI; prints the voxels reached of the
# structure's, and the last slice reached (59 = the whole length). Further arguments go to
# `segment` (e.g. --no-thin-fronts: the paper's sparse field, which stops in 1-2 voxel structures;
# --step exact).
# Usage: bash scripts/thin_structures.sh BIN [OUT_DIR [segment options...]]   (python3-nibabel)
set -eu
BIN=$1; OUT=${2:-/tmp/thin_structures}; mkdir -p "$OUT"; shift; [ $# -gt 0 ] && shift
/usr/bin/python3 - "$OUT" <<'PY'
import sys, numpy as np, nibabel as nib
out = sys.argv[1]; rng = np.random.default_rng(1)
for w in (1, 2, 3):
    a = np.zeros((64, 24, 24), np.float32); a[2:9, 8:15, 8:15] = 100
    a[8:60, 12 - w // 2:12 - w // 2 + w, 12 - w // 2:12 - w // 2 + w] = 100
    nib.save(nib.Nifti1Image(a + rng.normal(0, 2, a.shape).astype(np.float32), np.eye(4)), f'{out}/tube{w}.nii.gz')
    b = np.zeros((64, 24, 24), np.float32); b[2:9, 4:20, 8:15] = 100; b[8:60, 4:20, 12:12 + w] = 100
    nib.save(nib.Nifti1Image(b + rng.normal(0, 2, b.shape).astype(np.float32), np.eye(4)), f'{out}/sheet{w}.nii.gz')
PY
for f in tube1 tube2 tube3 sheet1 sheet2 sheet3; do
    "$BIN" segment "$OUT/$f.nii.gz" --roi none --seed 5,11,11 --mu-raw 100 --epsilon-raw 30 --alpha 0 --no-bias-correct \
        --out-mask "$OUT/$f.seg.nii.gz" -q "$@"
    /usr/bin/python3 -c "
import nibabel as nib, numpy as np
s = np.asarray(nib.load('$OUT/$f.seg.nii.gz').dataobj) > 0; a = np.asarray(nib.load('$OUT/$f.nii.gz').dataobj) > 50
print('$f: %d of %d voxels, last slice reached %d of 59' % (s.sum(), a.sum(), np.nonzero(s.any(axis=(1, 2)))[0].max()))"
done
