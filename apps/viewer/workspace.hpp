// The viewer's workspace: everything needed to continue where the user left off, in one versioned
// JSON file W (image and ROI paths, the image's geometry and a checksum of its voxels, seeds, µ, ε,
// n, α, the iteration count, the level-set step (--step, --thin-fronts, --coarse-start) and the sleeping step's
// wake stamps, swarm settings and target, camera, cursor) plus φ and the sparse
// field's layers bit for bit in W.state next to it (the recovery file's checksummed binary format,
// liveset/session/recovery.hpp). Both are written atomically, the state first; W records the
// state's checksum, so a W paired with another state is refused. Every read is checked and refused
// with one line (std::runtime_error): missing, truncated, another version, another image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "liveset/render/orbit_camera.hpp"
#include "liveset/session/session.hpp"

namespace liveset::viewer {

inline constexpr int kWorkspaceVersion = 1;

// The viewer's part of a workspace.
struct WorkspaceView {
    render::CameraPose camera = render::OrbitCamera::default_pose();
    Vec3i cursor{};
};

struct Workspace {
    std::string image, roi;          // absolute paths (roi "none" or, in older files, empty: none; "auto": the automatic brain mask, computed again)
    bool bias_corrected = false;     // the session's image was the N4-corrected one (absent in older files: no)
    Lattice lattice;                 // the image's geometry when saved
    std::uint64_t image_checksum = 0;  // image_checksum() of its voxels
    bool roi_recorded = false;                   // the file records the ROI's checksum (not in older files)
    std::optional<std::uint64_t> roi_checksum;  // mask_checksum() of the session's ROI (absent: saved without one)
    SessionMarks marks;              // seeds, parameters, iterations
    // The step it was saved stepping: its --step name ("sleeping" or "exact"; absent in files
    // written before session 72: the command line's) and the thin-front rule (false in those: it
    // was off unless asked for).
    std::optional<std::string> step;
    std::optional<bool> thin_fronts;
    // Its --coarse-start (absent in files written before session 82: the command line's). It
    // matters while φ is still the seeds: a Run from there starts coarse or not as saved.
    std::optional<CoarseStart> coarse_start;
    RepairOptions repair;            // swarm settings
    std::optional<Vec3d> target;     // the swarm's target (the swarm respawns there)
    WorkspaceView view;
    Grid<float> phi;                 // bit for bit as saved
    Grid<std::int8_t> status;
    ActivitySnapshot activity;       // the sleeping step's memory (bit-exact continuation)
};

// FNV-1a of the image's voxel values (float bits, in index order).
std::uint64_t image_checksum(const Grid<float>& image);
// (The ROI's checksum: mask_checksum, liveset/session/recovery.hpp.)
// The state file next to a workspace file: "<W>.state".
std::filesystem::path workspace_state_path(const std::filesystem::path& workspace);

// Writes W.state then W atomically. `image` and `roi` are made absolute (a `roi` of "auto" is kept); `bias_corrected`: the
// session's image is image's N4-corrected copy. Throws std::runtime_error.
void save_workspace(const std::filesystem::path& path, const Session& session, const std::string& image, const std::string& roi,
                    bool bias_corrected, const WorkspaceView& view);
// Reads and checks W and W.state. Throws std::runtime_error with one line naming the file.
Workspace read_workspace(const std::filesystem::path& path);
// Throws std::runtime_error when `ws` was saved for another image (geometry or voxels differ;
// named as a changed ROI when N4 was fitted in one that changed). `roi`: the ROI it is opened with,
// given as `roi_source` (a path or "auto"; empty without one).
void check_workspace_image(const Workspace& ws, const std::filesystem::path& path, const Grid<float>& image,
                           const Grid<std::uint8_t>* roi, const std::string& roi_source);
// A warning when the ROI the workspace is continued with (`session`'s, given as `roi_source`) is not
// the one it was saved with: another ROI given, none, one where it had none, a ROI file changed on
// disk, or "auto" computed again by another liveset; the level set continues as saved but the front
// may move where it could not. Empty when they agree or the file recorded nothing.
std::string workspace_roi_warning(const Workspace& ws, const std::filesystem::path& path, const Session& session,
                                  const std::string& roi_source);
// Continues the workspace in `session` (the image it was saved for): φ and the layers bit for bit,
// seeds, parameters and iteration count, swarm settings and target (the step is the session's
// options': `liveset view` builds the session with the workspace's). Throws std::invalid_argument.
void apply_workspace(Session& session, const Workspace& ws);

}  // namespace liveset::viewer
