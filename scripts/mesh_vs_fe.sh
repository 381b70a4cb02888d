#!/bin/sh
# Whole-volume meshing, liveset's marching_cubes_slabs vs VTK's vtkFlyingEdges3D (issue 16 item 3),
# side by side in one loop: per round and φ file, mesh_file_bench (1 and 2 threads, 5 repetitions)
# then the VTK peer (1 and 2 threads, 7 repetitions), with the load average before and after.
# Needs build/bench/mesh_file_bench and build-peer/bench/peers/vtk_flying_edges (docs/peers/vtk_flying_edges.md).
# Usage: scripts/mesh_vs_fe.sh PHI [PHI ...]   (ROUNDS=2 by default)
[ $# -ge 1 ] || { echo "usage: scripts/mesh_vs_fe.sh PHI [PHI ...]" >&2; exit 2; }
cd "$(dirname "$0")/.." || exit 1
for round in $(seq "${ROUNDS:-2}"); do
  for phi in "$@"; do
    echo "== round $round $phi load $(cut -d' ' -f1 /proc/loadavg)"
    ./build/bench/mesh_file_bench --phi "$phi" --benchmark_filter=BM_FileSlabs --benchmark_repetitions=5 \
      --benchmark_report_aggregates_only=true 2>&1 | grep median
    for t in 1 2; do ./build-peer/bench/peers/vtk_flying_edges --phi "$phi" --threads "$t" --reps 7; done
    echo "   load $(cut -d' ' -f1 /proc/loadavg)"
  done
done
