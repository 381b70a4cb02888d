#!/bin/bash
# The coarse start against the direct run (docs/BENCHMARKS.md, session 78): IMAGE's whole default
# `liveset segment` from the issue's 8 seeds in mm, 2 threads, `--coarse-start off` and `auto`
# alternately for ROUNDS rounds; one line per run (wall from the shell, the 1-minute load before it,
# the fine stage's iterations and seconds, the coarse stage's), then the two masks' md5.
# Usage: bash scripts/coarse_start_rotation.sh BIN IMAGE ROUNDS [OUT_DIR=/tmp/coarse_start_rotation]
set -eu
BIN=$1; IMG=$2; R=$3; OUT=${4:-/tmp/coarse_start_rotation}; mkdir -p "$OUT"
S=(--seed-mm 35,83,113 --seed-mm 35,125,38 --seed-mm 44,164,92 --seed-mm 71,74,53 --seed-mm 122,149,47 --seed-mm 140,86,74 --seed-mm 38,71,26 --seed-mm 83,23,71)
for _ in $(seq "$R"); do
  for m in off auto; do
    l=$(cut -d' ' -f1 /proc/loadavg); s=$(date +%s.%N)
    "$BIN" --threads 2 segment "$IMG" "${S[@]}" --coarse-start $m --out-mask "$OUT/$m.nii.gz" --json > "$OUT/$m.json"
    w=$(echo "$(date +%s.%N) $s" | awk '{printf "%.2f", $1-$2}')
    /usr/bin/python3 - "$OUT/$m.json" "$m" "$w" "$l" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); c = j['coarse_start']
coarse = 'coarse %d its %.2f s' % (c['iterations'], c['seconds']) if c else 'no coarse start'
print('%s wall=%s load=%s fine %d its %.2f s, %s' % (sys.argv[2], sys.argv[3], sys.argv[4], j['iterations'], j['seconds'], coarse))
PY
  done
done
md5sum "$OUT/off.nii.gz" "$OUT/auto.nii.gz"
