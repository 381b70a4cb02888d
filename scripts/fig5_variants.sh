#!/bin/bash
# The paper's Figure 5 scenario (`liveset demo --brain --repair`) on intensity variants of the
# bundled BrainWeb T1 (scripts/brainweb_variants.py: other units, gamma, noise, bias, skull-stripped),
# each judged against the truth by scripts/judge_repair.py (nibabel): a stand-in for the held-out
# scans the issue-18 targets are checked on. The anatomy is BrainWeb's, so the demo's seeds stay valid.
# Usage: scripts/fig5_variants.sh OUT_DIR [VARIANT...]   (default: all but 'orig'; needs build/liveset)
set -euo pipefail
out=${1:?usage: scripts/fig5_variants.sh OUT_DIR [VARIANT...]}; shift
here=$(cd "$(dirname "$0")/.." && pwd)
variants=("$@")
[ ${#variants[@]} -eq 0 ] && variants=(scaled gamma07 gamma14 noise bias25 biasnoise stripped)
mkdir -p "$out"
/usr/bin/python3 "$here/scripts/brainweb_variants.py" "$out/nii" >/dev/null
for v in "${variants[@]}"; do
    d="$out/data_$v"; mkdir -p "$d"
    # MetaImage with the original header's geometry (same grid), float voxels.
    /usr/bin/python3 - "$out/nii/$v.nii.gz" "$d/t1.mha" <<'PY'
import sys, nibabel as nib, numpy as np
a = np.asarray(nib.load(sys.argv[1]).dataobj, dtype=np.float32)
hdr = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
       "TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 0 0 0\nCenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\n"
       "ElementSpacing = 1 1 1\nDimSize = %d %d %d\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n" % a.shape)
with open(sys.argv[2], 'wb') as f:
    f.write(hdr.encode()); f.write(np.ascontiguousarray(a.transpose(2, 1, 0)).astype('<f4').tobytes())
PY
    cp "$here/data/brainweb/labels_crisp.nii.gz" "$here/data/brainweb/brain_mask.nii.gz" "$d/"
    "$here/build/liveset" --threads 1 demo --brain --repair --data "$d" --out "$out/run_$v" --json > "$out/run_$v.json"
    echo "== $v: $(/usr/bin/python3 "$here/scripts/judge_repair.py" "$out/run_$v" "$d/labels_crisp.nii.gz" | tail -1)"
done
