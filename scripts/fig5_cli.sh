#!/bin/bash
# The paper's Figure 5 through the general commands, as a user repairs a scan of their own (no demo
# code): segment with the tissue model's window narrowed as `demo --brain --repair` does (ε × 0.8, at
# least 2.4 σ of the grey-matter class, α 0.1 as the demo) -> `liveset repair --find-holes 10` on the bias-corrected image
# -> scripts/judge_repair.py against the truth. Seeds: the demo's eight, in physical mm (BrainWeb's
# LPS mm = its voxel index), so any grid of BrainWeb's space works (scripts/brainweb_geometry.py).
# Usage: scripts/fig5_cli.sh T1 BRAIN_MASK LABELS OUT_DIR   (needs build/liveset; T1/mask NIfTI, MINC, ...)
set -euo pipefail
t1=${1:?usage: scripts/fig5_cli.sh T1 BRAIN_MASK LABELS OUT_DIR}; mask=${2:?}; labels=${3:?}; out=${4:?}
here=$(cd "$(dirname "$0")/.." && pwd)
L="$here/build/liveset"
S=(--seed-mm 35,83,113 --seed-mm 35,125,38 --seed-mm 44,164,92 --seed-mm 71,74,53 --seed-mm 122,149,47
   --seed-mm 140,86,74 --seed-mm 38,71,26 --seed-mm 83,23,71)
mkdir -p "$out"
# 1. The window the tissue model gives the seeds (one iteration: only the report's window is used).
"$L" segment "$t1" "${S[@]}" --roi "$mask" --bias-correct --out-corrected "$out/corrected.nii.gz" --iterations 1 \
    --out-mask "$out/window_probe.nii.gz" --json > "$out/window.json"
read -r mu eps < <(/usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1])); w = j['window']; m = j['tissue_model']
sigma = m['classes'][m['seed_class']['index']]['sigma']
print(w['mu_raw'], max(0.8 * w['epsilon_raw'], min(w['epsilon_raw'], 2.4 * sigma)))" "$out/window.json")
# 2. The sub-optimally low threshold that leaves holes.
"$L" segment "$t1" "${S[@]}" --roi "$mask" --bias-correct --mu-raw "$mu" --epsilon-raw "$eps" --alpha 0.1 \
    --out-mask "$out/seg.nii.gz" --out-phi "$out/phi.nii.gz" --quiet
# 3. The truth-free repair on the corrected image.
"$L" repair "$out/phi.nii.gz" --image "$out/corrected.nii.gz" --roi "$mask" --find-holes 10 \
    --out-mask "$out/seg_repaired.nii.gz" --json > "$out/report.json"
echo "window mu $mu eps $eps: $(/usr/bin/python3 "$here/scripts/judge_repair.py" "$out" "$labels" | tail -1)"
