// Session scripts (`liveset view --script session.json`): a JSON list of actions replayed against
// the viewer - for tests, documentation pictures and the demo. The whole script is parsed and
// checked before anything runs (unknown keys, wrong types, points outside the image, unwritable
// output paths), each problem one line naming the entry: `script s.json entry 3 ("segment"): ...`.
//
//   {"seed": [i, j, k], "radius": 2}          seed ball (voxels); "remove_seed": [i, j, k]
//   {"params": {"mu": .., "epsilon": .., "n": .., "alpha": .., "smooth_mm": .., "auto_window": true, "auto_alpha": true,
//               "preset": "demo", "agents": 200, "p": 0.1, "radius": 3, "amount": .., "seed": ..,
//               "expand_sigmas": .., "contract_sigmas": .., "edit_range": .., "sample_depth": ..}}
//   {"segment": 100} or {"segment": "converge", "max": 2000}
//   {"click": [x, y]}                          pixel of the 3D pane: pick -> swarm target
//   {"target": [i, j, k]}  {"target_surface_near": [i, j, k], "radius": 20}
//   {"swarm": 300}  {"clear_target": true}   (the swarm goes away)
//   {"camera": {"view": "superior", "yaw": 0, "pitch": 90, "zoom": 1.2, "pan": [x, y, z], "center": [i, j, k],
//               "reset": true}}                 ("center": orbit around this voxel instead of the surface's centre)
//   {"cursor": [i, j, k]}  {"layout": "four" | "3d" | "axial" | "sagittal" | "coronal"}  {"tool": "seed"}
//   {"undo": 1}  {"redo": 1}
//   {"display": {"pane": "axial", "zoom": 3, "center": [i, j, k], "window": "auto" | "minmax" | "narrow" | [low, high],
//                "label_opacity": 0.4, "roi": "off" | "outline" | "tint", "preview": true, "contour": true}}
//        slice panes: a pane's zoom (about a voxel, default the slice's centre), window/level,
//        the overlay; only the given fields change
//   {"save_mask": path}  {"save_phi": path}  {"save_mesh": path}
//   {"save_workspace": path}  {"save_seeds": path}  {"load_seeds": path}   (workspace.hpp, seed_file.hpp)
//   {"screenshot": path, "pane": "3d" | "axial" | ... | "window", "size": [w, h], "supersample": 2}
//   {"eval": {"truth": path, "label": 2}}      prints {"entry": k, "eval": {dice, holes, ...}}
//   {"perforations": {"labels": path, "truth_label": 2, "inner_label": 3, "target": 0}}
//        prints the tunnels through the segmented shell where the truth is intact (largest first,
//        find_perforations) and, with "target": r, aims the swarm at the r-th largest - what a
//        user sees and clicks; as the demo does
//   {"find_holes": {"min_voxels": 10, "min_sheet_share": 0.1, "sheet_band": [low, high]}}  (or {})
//        the truth-free hole finder on the current segmentation (as the panel's Find holes; the
//        band from the tissue model unless given): prints {"entry": k, "holes": {count, ms, band,
//        sites [{rank, voxels, target (0-based, as --target), voxel1 (1-based)}], verdicts on the
//        sites the swarm repaired since the previous find [{target, before, after, closed}]}}
//   {"select_hole": rank}   the rank-th candidate (1-based): cursor there, the swarm's target
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "liveset/grid/lattice.hpp"
#include "liveset/render/orbit_camera.hpp"
#include "liveset/segment/threshold_speed.hpp"
#include "liveset/swarm/repair.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

struct ScriptAction {
    enum class Kind {
        kSeed, kRemoveSeed, kParams, kSegment, kClick, kTarget, kTargetSurfaceNear, kSwarm, kCamera, kCursor, kLayout,
        kTool, kUndo, kRedo, kSaveMask, kSavePhi, kSaveMesh, kScreenshot, kEval, kPerforations, kClearTarget, kDisplay,
        kSaveWorkspace, kSaveSeeds, kLoadSeeds, kFindHoles, kSelectHole
    };
    Kind kind = Kind::kSeed;
    std::size_t entry = 0;  // 1-based position in the script
    std::string name;       // the action's key, for messages
    Vec3d point{};
    double radius = 2.0;
    int count = 1;                 // steps, undo/redo count
    bool until_converged = false;  // segment
    double x = 0.0, y = 0.0;       // click pixel
    // params: only the given fields change
    std::optional<double> mu, epsilon, n, alpha, smooth_mm;
    std::optional<bool> auto_window, auto_alpha;
    nlohmann::json repair_fields;         // kept to apply onto the current options
    // camera
    std::optional<std::string> view;
    std::optional<double> yaw, pitch, zoom;
    std::optional<glm::dvec3> pan;
    std::optional<Vec3d> center;  // voxel to orbit around
    bool reset = false;
    std::optional<Pane> pane;  // layout / screenshot (nullopt: four panes / the window)
    Tool tool = Tool::kCrosshair;
    std::string path;
    int width = 0, height = 0, supersample = 1;
    int label = 0;  // eval: truth label (0: any non-zero); perforations: truth label
    int inner_label = 0;           // perforations: the tissue the shell encloses
    std::optional<int> rank;       // perforations: target the rank-th largest
    bool overlays = true;          // screenshot: bounding box and crosshair
    nlohmann::json display;        // display: the validated object
    HoleScanOptions hole_scan;     // find_holes
};

struct Script {
    std::string path;
    std::vector<ScriptAction> actions;
};

// Reads and validates a script for an image on `lattice`. Throws cli::UsageError (one line).
Script parse_script(const std::string& path, const Lattice& lattice);
// The same from JSON text (`path` names it in messages).
Script parse_script_text(const std::string& text, const std::string& path, const Lattice& lattice);

// Applies a "params" entry's swarm fields onto `options` (validated by the parser).
RepairOptions apply_repair_fields(RepairOptions options, const nlohmann::json& fields);

}  // namespace liveset::viewer
