// The paper's Figure 3 experiment: a box contracts under mean curvature flow; after every level-set
// step a fragment size re-meshes from the step's changed points X, and only "find and re-polygonise
// the affected fragments" (FragmentMesher::update) is timed, so the level-set cost is excluded.
// Each column runs its own flow from the start with its mesher alone (as a session re-meshes with
// its one mesher: no other column's meshes share its caches, which cost the small fragment sizes
// 10-15 % when every column re-meshed after each step of one flow); the flow is deterministic, and
// every column is checked to see the same X, step for step, as the first.
//
// Columns: x<S> for each fragment size S (cells per fragment edge). A size whose single fragment
// covers the whole lattice (S >= lattice - 1 cells) is the paper's naive method: every cell of the
// lattice is scanned every step (CellPolygoniser::polygonise_box into one reused mesh, with none of
// the incremental mesher's bookkeeping; O(volume)), whether or not anything changed. x<L>_band (L =
// lattice points per edge) is the same whole-lattice fragment updated band-driven
// (FragmentMesher::update, O(surface)). After the box vanishes the level set stops; the remaining
// steps have no changed points (incremental columns pay only the empty update) while the naive
// column keeps scanning the lattice, as a renderer re-meshing every frame would.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace liveset {

struct Figure3Options {
    int steps = 1500;
    int lattice = 100;        // points per edge
    int box = 50;             // box edge (points)
    int verify_every = 250;   // compare every mesh with marching_cubes_band every K steps (0: start and end only)
    std::vector<int> sizes{3, 5, 10, 20, 25, 50, 100};  // fragment sizes (cells per edge)
    // Throws std::invalid_argument naming the field ("steps", "lattice", "box", "verify_every",
    // "sizes") and the bad value.
    void validate() const;
};

struct Figure3Column {
    std::string name;                // "x10", ..., "x100_band"
    bool naive = false;              // whole-lattice scan every step
    std::size_t fragments = 1;
    std::vector<double> cumulative;  // seconds after each step
    double total_s = 0.0;
    std::size_t rebuilt_sum = 0, rebuilt_max = 0;  // fragments re-polygonised per step
    std::size_t vertices_only_sum = 0;             // of rebuilt_sum: T kept, only V recomputed
    std::size_t cells_sum = 0;                     // cells visited
};

struct Figure3Result {
    std::vector<Figure3Column> columns;  // the sizes in order, then the band-only column
    int flow_steps = 0;                  // level-set steps before the box vanished (≤ steps)
    double level_set_s = 0.0;            // their total time (not part of any column)
    std::size_t changed_sum = 0;         // Σ |X|
    int checks = 0;                      // mesh comparisons each column passed
};

// Runs the experiment. Throws std::runtime_error when a column's mesh differs from
// marching_cubes_band of the current φ (a check) or a column's flow gives another X than the
// first's, std::invalid_argument on bad options.
Figure3Result run_figure3(const Figure3Options& options);

}  // namespace liveset
