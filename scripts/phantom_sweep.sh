#!/bin/sh
# The phantom repair sweep (issue 18 item 5): liveset demo at sizes 64, 96, 128 x phantom seeds 1-3
# with one repair rule; one line per case: size seed dice_before dice_after holes_before holes_after,
# then the repaired mask's topology judged independently of liveset by scripts/phantom_topology.py
# (b0 b1 b2, whether the white-matter core is sealed, spurious cavities): `holes` 0 alone can hide an
# open core balanced by a bubble.
# Usage: scripts/phantom_sweep.sh [sheet-fallback|intensity|sheet] [BUILD=build]
rule=${1:-sheet-fallback}; build=${2:-build}; tmp=$(mktemp -d)
here=$(dirname "$0")
for size in 64 96 128; do
  for seed in 1 2 3; do
    "$build/liveset" --threads 1 demo --size "$size" --seed "$seed" --repair-rule "$rule" --out "$tmp/d" --json --no-view |
      /usr/bin/python3 -c "import json,sys; d=json.load(sys.stdin); b,a=d['before'],d['after']; print($size, $seed, '%.4f %.4f %d %d' % (b['dice'], a['dice'], b['holes'], a['holes']), end=' | ')"
    /usr/bin/python3 "$here/phantom_topology.py" "$tmp/d"
  done
done
rm -rf "$tmp"
