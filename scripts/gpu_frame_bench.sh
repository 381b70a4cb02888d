#!/usr/bin/env bash
# The viewer's frame benchmark (the paper's FPS experiment: static, 200 agents moving, repairing at
# p = 0.1 and 0.5) and its interaction latency, headless, on whatever OpenGL this machine's EGL
# gives (surfaceless, else an EGL device: Mesa's llvmpipe or a GPU driver). Writes one JSON file per run into OUTDIR.
#   usage: scripts/gpu_frame_bench.sh OUTDIR GM_PHI [PHANTOM_T1 PHANTOM_PHI]
#   env:   LIVESET (./build/liveset), FRAMES (1000), SIZES ("1280x720 1920x1080")
# GM_PHI: the BrainWeb grey-matter φ of the README's 8-seed segmentation (segment --out-phi).
set -euo pipefail
out=${1:?usage: $0 OUTDIR GM_PHI [PHANTOM_T1 PHANTOM_PHI]}
gm_phi=${2:?usage: $0 OUTDIR GM_PHI [PHANTOM_T1 PHANTOM_PHI]}
ph_t1=${3:-}
ph_phi=${4:-}
liveset=${LIVESET:-./build/liveset}
frames=${FRAMES:-1000}
sizes=${SIZES:-1280x720 1920x1080}
B=data/brainweb
mkdir -p "$out"
run() {  # NAME ARGS...: one benchmark, its JSON to OUTDIR/NAME.json, a failure reported and skipped
    local name=$1
    shift
    local t0=$SECONDS
    if timeout 300 "$liveset" view "$@" --headless --json >"$out/$name.json" 2>"$out/$name.err"; then
        echo "$name: $((SECONDS - t0)) s"
    else
        echo "$name: FAILED ($(tail -1 "$out/$name.err"))"
    fi
}
for size in $sizes; do
    run "brainweb_frames_$size" "$B/t1.mha" --roi "$B/brain_mask.nii.gz" --phi "$gm_phi" --bench --bench-frames "$frames" --size "$size"
done
run brainweb_interaction "$B/t1.mha" --roi "$B/brain_mask.nii.gz" --phi "$gm_phi" --bench --bench-mode interaction
if [[ -n "$ph_t1" ]]; then
    for size in $sizes; do
        run "phantom_frames_$size" "$ph_t1" --phi "$ph_phi" --bench --bench-frames "$frames" --size "$size"
    done
fi
