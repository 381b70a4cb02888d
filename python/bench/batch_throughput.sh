#!/usr/bin/env bash
# Subjects per minute of `liveset batch` (1 and 2 Dask workers) against a plain shell loop of
# `liveset segment` on the same N phantoms (each writes mask + phi). Median of REPS interleaved runs each.
# Usage: python/bench/batch_throughput.sh [N=8] [SIZE=96] [REPS=3]   (from the repository root)
set -euo pipefail
n=${1:-8}; size=${2:-96}; reps=${3:-3}
cli=$PWD/build/liveset
work=$(mktemp -d /tmp/liveset-batch-bench.XXXXXX)
trap 'rm -rf "$work"' EXIT
echo "subject,image,seeds" > "$work/manifest.csv"
for k in $(seq 1 "$n"); do
  "$cli" phantom --out "$work/s$k" --size "$size" --seed "$k" --quiet
  seeds=$(/usr/bin/python3 -c "import json,sys; print(';'.join(','.join(map(str,s)) for s in json.load(open(sys.argv[1]))['seeds']))" "$work/s$k/phantom.json")
  echo "sub-$k,s$k/t1.nii.gz,\"$seeds\"" >> "$work/manifest.csv"
done
loop() {
  tail -n +2 "$work/manifest.csv" | while IFS=, read -r subject image seeds_rest; do
    seeds=${seeds_rest//\"/}; args=()
    IFS=';' read -ra list <<< "$seeds"; for s in "${list[@]}"; do args+=(--seed "$s"); done
    "$cli" segment "$work/$image" "${args[@]}" --out-mask "$work/loop-$subject.nii.gz" --out-phi "$work/loop-phi-$subject.nii.gz" --quiet
  done
}
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
timed() {  # seconds of one run of the command
  rm -rf "$work/out"
  local t0; t0=$(date +%s.%N); "$@" > /dev/null; local t1; t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" "BEGIN {print b - a}"
}
uptime
# Interleaved (loop, 1 worker, 2 workers; REPS rounds) so the machine's load hits all three alike.
for r in $(seq 1 "$reps"); do
  timed loop >> "$work/t-loop"
  timed "$cli" batch "$work/manifest.csv" --out "$work/out" --workers 1 --no-progress >> "$work/t-b1"
  timed "$cli" batch "$work/manifest.csv" --out "$work/out" --workers 2 --no-progress >> "$work/t-b2"
done
for m in "loop:shell loop (segment)" "b1:batch --workers 1" "b2:batch --workers 2"; do
  median < "$work/t-${m%%:*}" | awk -v n="$n" -v name="${m#*:}" -v all="$(tr '\n' ' ' < "$work/t-${m%%:*}")" \
    '{printf "%-22s median %6.2f s  %6.1f subjects/min  (runs: %s)\n", name, $1, 60*n/$1, all}'
done
uptime
