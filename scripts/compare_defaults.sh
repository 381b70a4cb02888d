#!/bin/bash
# Two liveset binaries' default choices on variant folders (docs/BENCHMARKS.md, session 66): for each
# DIR/{t1.nii.gz|t1.mgz} (seeded from DIR/seeds where a variant has one, else one seed at 35,83,113 mm)
# the default ROI's voxels, the window (µ, ε raw), α, the automatic mask's contrast and deep skew, and
# the voxels of the mask found again after N4, with `--iterations 1`; "same" or "DIFF" per variant.
# With ROI=file, each variant is given its own brain mask (DIR/mask.nii.gz or mask.mnc) as `--roi`
# (session 67), and the tissue model's contrast and floor are printed instead of the automatic mask's.
# Usage: [ROI=file] bash scripts/compare_defaults.sh OLD_BIN NEW_BIN DIR...
set -u
OLD=$1; NEW=$2; shift 2
one() {  # BIN FILE SEED-ARGS...
    local bin=$1 f=$2; shift 2
    "$bin" --threads 2 segment "$f" "$@" --iterations 1 --json --out-mask "${TMPDIR:-/tmp}/compare_defaults_$$.nii.gz" 2>/dev/null |
        /usr/bin/python3 -c "
import json, sys
j = json.load(sys.stdin); r = j.get('roi') or {}; a = r.get('auto') or {}; m = j.get('tissue_model') or {}
if '${ROI:-}' == 'file': a = {'contrast': m.get('contrast'), 'deep_skew': m.get('floor') or 0}
print(r.get('voxels'), round(j['window']['mu_raw'], 4), round(j['window']['epsilon_raw'], 4), round(j['alpha'], 5), a.get('contrast'),
      round(a.get('deep_skew', 0), 3), j.get('bias_correction', {}).get('brain_mask_after_voxels'))" 2>/dev/null || echo failed
}
for d in "$@"; do
    t=$d/t1.nii.gz; [ -f "$t" ] || t=$d/t1.mgz; [ -f "$t" ] || continue
    S=(--seed-mm 35,83,113); [ -f "$d/seeds" ] && read -r -a S < <(cut -d' ' -f1-2 "$d/seeds")
    if [ "${ROI:-}" = file ]; then
        m=$d/mask.nii.gz; [ -f "$m" ] || m=$d/mask.mnc; [ -f "$m" ] || continue
        S+=(--roi "$m")
    fi
    o=$(one "$OLD" "$t" "${S[@]}"); n=$(one "$NEW" "$t" "${S[@]}")
    [ "$o" = "$n" ] && echo "same $d: $n" || echo "DIFF $d: old $o | new $n"
done
rm -f "${TMPDIR:-/tmp}/compare_defaults_$$.nii.gz"
