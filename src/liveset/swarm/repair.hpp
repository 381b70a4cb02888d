// Headless hole repair (paper §4): a swarm spawned at the user's target walks the zero level set,
// proposes local edits each step, the edits go through the sparse field's *local* update, and the
// changed points X are returned for the caller to mesh (the Session does) — nothing else is recomputed. Targets can change
// over time (a user moving the mouse): target k takes effect from its step on.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/swarm/swarm.hpp"

namespace liveset {

struct RepairTarget {
    Vec3d position;  // index space
    int step = 0;    // first step at which it is the swarm's target
};

struct RepairOptions {
    SwarmOptions swarm;
    int steps = 300;
    double spawn_radius = 20.0;  // agents start on the zero-layer points nearest the first target
    // A new target farther than this (voxels) from the swarm's centroid respawns the swarm there,
    // as a click on another part of the surface would, instead of walking it across (0: never).
    double respawn_distance = 20.0;
    // Topology guard: an edit that would move a voxel across the surface in a way that bridges two
    // pieces, starts a new piece, opens a tunnel, seals a cavity by removal or splits a piece is
    // dropped (see guard_topology), so the swarm can close holes but never make new ones.
    bool topology_guard = true;
    // Cracks between fronts filled with the tunnel they belong to (GuardOptions::close_cracks).
    bool close_cracks = true;
};

struct RepairStepLog {
    int step = 0;
    std::size_t on_surface = 0;  // agents within |φ| < 0.5
    std::size_t modified = 0;    // zero-layer points edited this step
    std::size_t guarded = 0;     // edits dropped by the topology guard
    std::size_t changed = 0;     // |X| reported by the local update
    std::size_t fragments = 0;   // fragments re-polygonised (filled by whoever meshes X: the Session)
    double ms = 0.0;             // wall time of move + edits + level set + mesh
    // Of ms, the parts after the agents' move and edit proposals (wall time): the topology guard,
    // the sparse field's local update, and the mesher's (filled by whoever meshes X: the Session).
    double guard_ms = 0.0;
    double level_set_ms = 0.0;
    double mesh_ms = 0.0;
    // Processor time of the same (std::clock, all threads of the process): the wall time less what
    // other processes took while they held the core (on a shared machine, most of a slow step).
    double cpu_ms = 0.0;
};

struct GuardOptions {
    // Growth that seals a region of the outside off (walls it apart from the rest of the outside it
    // touched) is refused when that region holds at most this many voxels (a spurious cavity); a
    // larger one is tissue the sheet already enclosed around the hole (the white matter under a
    // perforation), and sealing it closes the hole. Growth that only shrinks a region, whose pieces
    // around the edit still join elsewhere, seals nothing, however small the region.
    std::size_t pocket_limit = 32768;
    // A growth edit refused as a bridge (its inside neighbours form two pieces: two fronts that
    // met with a one-voxel crack between them) fills the whole crack at once when that closes a
    // tunnel and seals no pocket (see guard_topology).
    bool close_cracks = true;
    const Grid<std::uint8_t>* roi = nullptr;  // crack voxels (and their face neighbours) must lie in it
    // Cutting a handle (EditDecision::kCut): a removal is kept only when it cuts a handle — the
    // point's inside neighbours form two 26-connected pieces, its outside neighbours one, and the
    // two pieces are joined elsewhere (no piece split off; see guard_topology) — the mirror of growth
    // that closes a tunnel; every other removal (a simple one too: the surface elsewhere in the
    // brush stays where it is) is dropped, and so is an edit raising φ anywhere else (see guard_topology).
    bool cut_handles = false;
};

// The pocket limit for a swarm whose brush is `edit_range` voxels (0: no brush): the voxels of the
// brush's cube, (2⌈r⌉ + 1)³, at most 32768 — a pocket the brush could have walled in is spurious,
// a larger one was enclosed before the swarm came.
std::size_t brush_pocket_limit(double edit_range);

// Drops, in point order, every edit that would flip the inside/outside state (φ < 0) of its point
// non-simply: growth is kept only when the point's inside neighbours form one 26-connected piece
// (no bridge, no new piece); shrinking only when the point is simple (no tunnel opened, no cavity
// made, nothing split) or an isolated inside voxel. Growth that closes a tunnel or fills a
// cavity is kept, growth that seals a pocket of at most options.pocket_limit voxels off is not (its
// outside face neighbours lie in two or more regions, one of them that small: see PocketFlood).
// Flips already accepted count for the later points. Returns the number dropped.
// Cracks (options.close_cracks): a bridge's crack is the outside voxels 6-connected to it that each
// lie between two inside voxels along one of the 13 directions through them, gathered along the
// whole slit (at most 512 voxels, all in the ROI); it is filled whole (every crack point's edit
// becomes −0.5) when the fill raises the Euler characteristic (counted in the box around the crack:
// it closes a tunnel), seals no pocket and each crack voxel is a zero-layer point that edit flips
// (φ < 0.5). When only the last fails, the inside zero-layer face neighbours of the voxels that
// cannot flip get −0.5 instead (no sign changes: the slit comes onto the zero layer for a later
// batch). Else the edit is dropped as before.
// Handle cuts (options.cut_handles): removals are kept only where they cut a handle: two inside
// pieces around the point, one outside piece, and the pieces joined by an inside path elsewhere —
// two 26-connected floods of the inside, one from each piece, grown by turns until they meet (kept)
// or one runs out (a piece would split off) or together they pass 2^21 voxels (dropped: not known);
// an edit that flips nothing raising φ is kept only where the inside neighbours form two or more
// pieces (a cut moves the surface nowhere else). A handle thick enough that no voxel of it has two
// inside pieces around it (e.g. a 2 x 2 neck) cannot be cut: every removal there is simple.
std::size_t guard_topology(const SparseField& field, std::vector<ZeroLayerEdit>& edits, const GuardOptions& options = {});

// Throws std::invalid_argument (one-line message) on an invalid option: the swarm's (validate),
// a negative step count, spawn radius ≤ 0, respawn distance < 0, or the cut decision without the
// topology guard (the guard is what keeps a cut to the removals that cut a handle).
void validate(const RepairOptions& options);

// One repair step's outcome: the log line plus the changed points X (for the mesher).
struct RepairStep {
    RepairStepLog log;
    ChangedPoints changed;
};

// The interactive repair loop, one step at a time (the Session calls step() and meshes X): swarm
// move -> surface edits (ROI and topology guard applied) -> local level-set update. The swarm is spawned on the surface nearest the first target; later
// targets re-aim it (respawn() moves it at once, as a click far from the swarm would).
class RepairLoop {
public:
    // `field`, `image_unit` and `roi` must outlive the loop. Throws std::invalid_argument on bad
    // options or sizes.
    RepairLoop(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi, const RepairOptions& options);

    // Aims the swarm at `target` (index space, inside the lattice); spawns it there first if it
    // has no agents yet or the target is farther than options.respawn_distance from its centroid. Throws std::invalid_argument outside the lattice or when no surface lies
    // within options.spawn_radius of a first target.
    void set_target(Vec3d target);
    // Spawns the swarm afresh on the surface nearest `target` and aims it there.
    void respawn(Vec3d target);
    bool spawned() const { return spawned_; }
    const Swarm& swarm() const { return swarm_; }
    Swarm& swarm() { return swarm_; }

    // One step (a no-op step with zero counts before the first target).
    RepairStep step();

private:
    SparseField& field_;
    const Grid<float>& image_unit_;
    const Grid<std::uint8_t>* roi_;
    RepairOptions options_;
    Swarm swarm_;
    bool spawned_ = false;
    int steps_ = 0;
};

// Runs `options.steps` swarm steps of a RepairLoop, target k taking effect from its step on.
// Stops early when `interrupt` turns true. Throws std::invalid_argument on bad targets/options.
std::vector<RepairStepLog> run_repair(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                      std::span<const RepairTarget> targets, const RepairOptions& options,
                                      const std::atomic<bool>* interrupt = nullptr);

}  // namespace liveset
