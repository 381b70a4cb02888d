#!/bin/bash
# The Dice of one BrainWeb variant segmented from the issue's 8 seeds (docs/BENCHMARKS.md, sessions
# 50-54): VARIANTS/NAME/{t1.nii.gz|t1.mnc|t1.mgz, labels.nii.gz, mask.nii.gz} as the variant scripts write.
# Usage: [ROI=auto|none|default] [VARIANTS=DIR] bash scripts/variant_dice.sh BIN NAME TAG [segment options...]
# A variant folder holding a `seeds` file (brainweb_slab_variants.py --unoriented) is seeded from it.
# Default ROI: the variant's brain mask. ROI=default gives no --roi (since session 59 the automatic brain
# mask on a full head; before, no ROI); ROI=none gives --roi none (binaries from session 59 on).
# Prints name, tag, exit status, wall time, Dice (label 2), iterations (ROI=auto, and ROI=default where
# it chose the automatic mask: that mask's Dice against the variant's mask).
set -u
BIN=$1; V=$2; TAG=$3; shift 3
D=${VARIANTS:-brainweb-noise-variants}/$V; OUT=${OUT:-/tmp/variant_dice}; mkdir -p "$OUT"
S=(--seed-mm 35,83,113 --seed-mm 35,125,38 --seed-mm 44,164,92 --seed-mm 71,74,53 --seed-mm 122,149,47 --seed-mm 140,86,74 --seed-mm 38,71,26 --seed-mm 83,23,71)
[ -f "$D/seeds" ] && read -r -a S < "$D/seeds"  # the seeds as voxels of a variant without orientation
T1=$D/t1.nii.gz; [ -f "$T1" ] || T1=$D/t1.mnc; [ -f "$T1" ] || T1=$D/t1.mgz
M=$D/mask.nii.gz; [ -f "$M" ] || M=$D/mask.mnc
R=(--roi "$M"); [ "${ROI:-}" = none ] && R=(--roi none); [ "${ROI:-}" = default ] && R=()
[ "${ROI:-}" = auto ] && R=(--roi auto --out-roi "$OUT/${V}_${TAG}_roi.nii.gz")
s=$(date +%s.%N)
"$BIN" --threads 2 segment "$T1" "${S[@]}" "${R[@]}" --out-mask "$OUT/${V}_$TAG.nii.gz" --json "$@" > "$OUT/${V}_$TAG.json" 2> "$OUT/${V}_$TAG.err"
rc=$?
w=$(echo "$(date +%s.%N) $s" | awk '{printf "%.1f", $1-$2}')
d=$(/usr/bin/python3 - "$OUT/${V}_$TAG" "$D/labels.nii.gz" "$M" <<'PY'
import json, os, sys
import nibabel as nib, numpy as np
base, labels, truth = sys.argv[1:4]
dice = lambda a, b: 2 * (a & b).sum() / (a.sum() + b.sum())
try:
    m = np.asarray(nib.load(base + '.nii.gz').dataobj) > 0
    l = np.asarray(nib.load(labels).dataobj) == 2
    j = json.load(open(base + '.json'))
    roi = ''
    if os.path.exists(base + '_roi.nii.gz'):  # ROI=auto: the brain mask against the variant's
        roi = ' roi_dice=%.4f' % dice(np.asarray(nib.load(base + '_roi.nii.gz').dataobj) > 0, np.asarray(nib.load(truth).dataobj) > 0)
    if 'roi' in j and j['roi'].get('default') and not roi:
        roi = ' roi=default(%d)' % j['roi']['voxels']
    print('%.4f its=%s smooth_mm=%s%s' % (dice(m, l), j.get('iterations'), j.get('smooth_mm'), roi))
except Exception as e:
    print('none (%s)' % type(e).__name__)
PY
)
echo "$V $TAG rc=$rc wall=${w}s dice=$d load=$(cut -d' ' -f1 /proc/loadavg)"
