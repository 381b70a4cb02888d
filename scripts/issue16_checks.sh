#!/usr/bin/env bash
# Issue 16's speed checks in one run (docs/BENCHMARKS.md): per iteration against ITK's threshold
# level set (3 rounds on 1 thread pinned to core 0, 3 on 2 threads), the BrainWeb wall time and
# mask, the box flow against ITK's, Figure 3, whole-volume meshing against VTK's Flying Edges, and
# the swarm's step times; the load average and the time between stages. Needs `bash scripts/setup.sh
# --peers` (./build and ./build-peer). Prints everything on stdout; logs and outputs go to OUT.
# ITK's filters keep as many layers on each side as the image has dimensions (3) unless told;
# liveset keeps 2. ITK_LAYERS=2 runs ITK (threshold level set and box flow) with liveset's band
# (the same segmentation, 0.66-0.91x the time per iteration: docs/BENCHMARKS.md, session 44);
# unset or 0, ITK's default.
# Usage: [ITK_LAYERS=N] scripts/issue16_checks.sh OUT [--itk-only]      (about 10 minutes on a 2-core VM)
set -euo pipefail
usage="usage: [ITK_LAYERS=N] scripts/issue16_checks.sh OUT [--itk-only]"
itk_layers=${ITK_LAYERS:-0}
[[ "$itk_layers" =~ ^[0-8]$ ]] || { echo "issue16_checks: ITK_LAYERS must be 0-8 (0: ITK's default), got '$itk_layers'" >&2; exit 2; }
[ $# -ge 1 ] && [ $# -le 2 ] || { echo "$usage" >&2; exit 2; }
itk_only=0
if [ $# -eq 2 ]; then
  [ "$2" = "--itk-only" ] || { echo "issue16_checks: unknown option $2 ($usage)" >&2; exit 2; }
  itk_only=1
fi
mkdir -p "$1"
out=$(cd "$1" && pwd)  # OUT as given from the caller's folder, before moving to the repository
cd "$(dirname "$0")/.."
for bin in build/liveset build/bench/mesh_file_bench build-peer/bench/peers/itk_threshold_levelset \
           build-peer/bench/peers/itk_box_flow build-peer/bench/peers/vtk_flying_edges; do
  [ -x "$bin" ] || { echo "issue16_checks: $bin is missing (run bash scripts/setup.sh --peers)" >&2; exit 1; }
done
B=data/brainweb
S8=(--seed 35,83,113 --seed 35,125,38 --seed 44,164,92 --seed 71,74,53 --seed 122,149,47 --seed 140,86,74 --seed 38,71,26 --seed 83,23,71)
# --no-bias-correct: ITK's filter below runs on the raw T1, and so does liveset, to compare one front
# (N4, the default since session 48, adds 0.5-0.8 s and changes the front: 716 iterations, Dice 0.939).
# --alpha 0.1: ITK runs with the curvature weight 0.1 maps to; liveset's automatic weight (session 50)
# would take 0 on this scan and make the two fronts differ. --no-thin-fronts: the paper's sparse field,
# as ITK's (the thin-front rule, liveset's default since session 72, costs 1.13-1.56x per iteration
# at equal front size and takes the front into thin cortex ITK's stops at: docs/BENCHMARKS.md).
segment=(segment "$B/t1.mha" "${S8[@]}" --roi "$B/brain_mask.nii.gz" --mu-raw 94 --epsilon-raw 22 --alpha 0.1 --no-bias-correct --no-thin-fronts --quiet)
load() { echo "-- load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%H:%M:%S) UTC"; }
summary() { /usr/bin/python3 -c 'import json, sys; d = json.load(sys.stdin); print({k: v for k, v in d.items() if not isinstance(v, (list, dict))})'; }

load
echo "ITK's layers on each side: $([ "$itk_layers" = 0 ] && echo "its default (3)" || echo "$itk_layers") (liveset: 2)"
for threads in 1 2; do
  pin=()
  [ "$threads" = 1 ] && pin=(taskset -c 0)
  for round in 1 2 3; do
    ./build-peer/bench/peers/itk_threshold_levelset --image "$B/t1.mha" --mask "$B/brain_mask.nii.gz" \
      --labels "$B/labels_crisp.nii.gz" "${S8[@]}" --iterations 600 --threads "$threads" --layers "$itk_layers" \
      --log "$out/itk${threads}_$round.jsonl" >/dev/null
    start=$(date +%s.%N)
    "${pin[@]}" ./build/liveset --threads "$threads" "${segment[@]}" --out-mask "$out/mask${threads}_$round.nii.gz" \
      --log "$out/ls${threads}_$round.jsonl"
    echo "liveset $threads thread(s), round $round: $(echo "$(date +%s.%N) $start" | awk '{printf "%.2f", $1 - $2}') s wall"
    load
  done
  echo "per iteration against ITK, $threads thread(s):"
  /usr/bin/python3 scripts/itk_per_iteration.py $(for r in 1 2 3; do echo "$out/itk${threads}_$r.jsonl $out/ls${threads}_$r.jsonl"; done)
done
echo "masks (md5, count):"
md5sum "$out"/mask?_?.nii.gz | cut -c1-8 | sort | uniq -c
((itk_only)) && exit 0

echo "box flow, 1 thread (ITK, then liveset), 3 rounds:"
for round in 1 2 3; do
  taskset -c 0 ./build-peer/bench/peers/itk_box_flow --threads 1 --layers "$itk_layers" | tail -1
  taskset -c 0 ./build/liveset --threads 1 flow --check-every 0 --json | summary
done
load
echo "Figure 3, 1 thread, 2 runs:"
for round in 1 2; do taskset -c 0 ./build/liveset --threads 1 bench fig3 --out "$out/fig3_$round" --no-plot | tail -12; done
load
echo "meshing against Flying Edges (BrainWeb GM phi, 256^3 sphere):"
./build/liveset --threads 2 "${segment[@]}" --out-mask "$out/gm.nii.gz" --out-phi "$out/gm_phi.nii.gz"
/usr/bin/python3 - "$out" <<'EOF'
import os, sys
import numpy as np
n, c = 256, 127.5
z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
phi = (np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2) - 100).astype(np.float32)
phi.tofile(os.path.join(sys.argv[1], "sphere.raw"))
with open(os.path.join(sys.argv[1], "sphere.mha"), "w") as f:
    f.write("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
            "DimSize = 256 256 256\nElementSpacing = 1 1 1\nElementType = MET_FLOAT\nElementDataFile = sphere.raw\n")
EOF
ROUNDS=2 sh scripts/mesh_vs_fe.sh "$out/gm_phi.nii.gz" "$out/sphere.mha"
load
echo "swarm at p = 0.5, 1 thread, 2 runs (mean steps/s, median, p99, max ms):"
./build/liveset demo --brain --repair --out "$out/demo" --no-view --quiet
for round in 1 2; do
  taskset -c 0 ./build/liveset --threads 1 repair "$out/demo/phi.nii.gz" --image "$B/t1.mha" --roi "$B/brain_mask.nii.gz" \
    --target 94,64,146 --agents 200 --steps 1000 --p 0.5 --decision random --log "$out/steps_$round.jsonl" \
    --out-mask "$out/swarm_$round.nii.gz" --json >/dev/null
  /usr/bin/python3 - "$out/steps_$round.jsonl" <<'EOF'
import json, statistics, sys
ms = sorted(json.loads(line)["ms"] for line in open(sys.argv[1]) if '"ms"' in line)
print(f"{1000 / statistics.mean(ms):.0f} steps/s, median {statistics.median(ms):.3f}, p99 {ms[int(0.99 * len(ms)) - 1]:.3f}, max {ms[-1]:.2f} ms")
EOF
done
md5sum "$out"/swarm_?.nii.gz | cut -c1-8
load
