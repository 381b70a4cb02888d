// Workspace files: W (JSON) + W.state (φ and layers, the recovery format), written and checked.
#include "workspace.hpp"

#include <fmt/core.h>

#include <bit>
#include <cmath>
#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "liveset/base/atomic_file.hpp"
#include "liveset/session/recovery.hpp"

namespace liveset::viewer {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json vec(Vec3d v) { return {v.x, v.y, v.z}; }

// One field of the workspace, of the expected type; std::runtime_error naming it otherwise.
const json& field(const json& j, const char* key) {
    if (!j.is_object() || !j.contains(key)) throw std::runtime_error(fmt::format("missing field '{}'", key));
    return j[key];
}

double number(const json& j, const char* key) {
    const json& v = field(j, key);
    if (!v.is_number()) throw std::runtime_error(fmt::format("field '{}' is not a number", key));
    return v.get<double>();
}

std::vector<double> numbers(const json& j, const char* key, std::size_t n) {
    const json& v = field(j, key);
    if (!v.is_array() || v.size() != n) throw std::runtime_error(fmt::format("field '{}' is not a list of {} numbers", key, n));
    std::vector<double> out;
    for (const json& x : v) {
        if (!x.is_number()) throw std::runtime_error(fmt::format("field '{}' is not a list of {} numbers", key, n));
        out.push_back(x.get<double>());
    }
    return out;
}

Vec3d vec3(const json& j, const char* key) {
    const auto v = numbers(j, key, 3);
    return {v[0], v[1], v[2]};
}

json swarm_json(const RepairOptions& r) {
    const SwarmOptions& s = r.swarm;
    return {{"agents", s.agents}, {"pull_back", s.pull_back}, {"attraction", s.attraction}, {"random_walk", s.random_walk},
            {"separation", s.separation}, {"separation_radius", s.separation_radius}, {"max_step", s.max_step},
            {"p", s.act_probability}, {"edit_radius", s.edit_radius}, {"edit_amount", s.edit_amount}, {"seed", s.seed},
            {"expand_sigmas", s.expand_sigmas}, {"contract_sigmas", s.contract_sigmas}, {"min_sigma", s.min_sigma},
            {"stats_smoothing", s.stats_smoothing}, {"sample_depth", s.sample_depth}, {"edit_range", s.edit_range},
            {"decision", static_cast<int>(s.decision)}, {"sheet_lower", s.sheet_lower}, {"sheet_upper", s.sheet_upper},
            {"sheet_between", s.sheet_between}, {"sheet_reach", s.sheet_reach},
            {"sheet_mean", std::isnan(s.sheet_mean) ? json(nullptr) : json(s.sheet_mean)},
            {"sheet_between_share", s.sheet_between_share}, {"sheet_between_limited", s.sheet_between_limited},
            {"spawn_radius", r.spawn_radius}, {"respawn_distance", r.respawn_distance}, {"topology_guard", r.topology_guard},
            {"close_cracks", r.close_cracks}};
}

RepairOptions swarm_from(const json& j, RepairOptions r) {
    SwarmOptions& s = r.swarm;
    s.agents = static_cast<std::size_t>(number(j, "agents"));
    s.pull_back = number(j, "pull_back");
    s.attraction = number(j, "attraction");
    s.random_walk = number(j, "random_walk");
    s.separation = number(j, "separation");
    s.separation_radius = number(j, "separation_radius");
    s.max_step = number(j, "max_step");
    s.act_probability = number(j, "p");
    s.edit_radius = number(j, "edit_radius");
    s.edit_amount = number(j, "edit_amount");
    s.seed = field(j, "seed").get<std::uint64_t>();
    s.expand_sigmas = number(j, "expand_sigmas");
    s.contract_sigmas = number(j, "contract_sigmas");
    s.min_sigma = number(j, "min_sigma");
    s.stats_smoothing = number(j, "stats_smoothing");
    s.sample_depth = number(j, "sample_depth");
    s.edit_range = number(j, "edit_range");
    const int decision = static_cast<int>(number(j, "decision"));
    if (decision < 0 || decision > static_cast<int>(EditDecision::kCut)) throw std::runtime_error("unknown swarm decision rule");
    s.decision = static_cast<EditDecision>(decision);
    s.sheet_lower = number(j, "sheet_lower");
    s.sheet_upper = number(j, "sheet_upper");
    s.sheet_between = field(j, "sheet_between").get<bool>();
    s.sheet_reach = number(j, "sheet_reach");
    // Absent from a workspace written before the between test's intensity limit: the defaults.
    if (j.contains("sheet_mean") && !j["sheet_mean"].is_null()) s.sheet_mean = number(j, "sheet_mean");
    if (j.contains("sheet_between_share")) s.sheet_between_share = number(j, "sheet_between_share");
    if (j.contains("sheet_between_limited")) s.sheet_between_limited = field(j, "sheet_between_limited").get<bool>();
    r.spawn_radius = number(j, "spawn_radius");
    r.respawn_distance = number(j, "respawn_distance");
    r.topology_guard = field(j, "topology_guard").get<bool>();
    r.close_cracks = field(j, "close_cracks").get<bool>();
    return r;
}

// The FNV-1a a recovery-format file ends with (its last 8 bytes).
std::uint64_t trailing_checksum(const std::vector<std::uint8_t>& bytes) {
    std::uint64_t h = 0;
    std::memcpy(&h, bytes.data() + bytes.size() - sizeof h, sizeof h);
    return h;
}

std::string read_text(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw std::runtime_error("no such file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read it");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// The sleeping step's memory: the wake stamps run-length encoded ([stamp, count] pairs in block
// order; neighbouring blocks mostly share a stamp).
json activity_json(const ActivitySnapshot& a) {
    json runs = json::array();
    for (std::size_t i = 0; i < a.stamps.size();) {
        std::size_t n = 1;
        while (i + n < a.stamps.size() && a.stamps[i + n] == a.stamps[i]) ++n;
        runs.push_back({a.stamps[i], n});
        i += n;
    }
    return {{"clock", a.clock}, {"all_woken_at", a.all_woken_at}, {"speed_current", a.speed_current},
            {"blocks", {a.blocks.x, a.blocks.y, a.blocks.z}}, {"runs", runs}};
}

ActivitySnapshot activity_from(const json& j) {
    ActivitySnapshot a;
    a.clock = field(j, "clock").get<std::int64_t>();
    a.all_woken_at = field(j, "all_woken_at").get<std::int64_t>();
    a.speed_current = field(j, "speed_current").get<bool>();
    const auto b = numbers(j, "blocks", 3);
    a.blocks = {static_cast<int>(b[0]), static_cast<int>(b[1]), static_cast<int>(b[2])};
    if (a.blocks.x < 0 || a.blocks.y < 0 || a.blocks.z < 0 || a.blocks.x > 65536 || a.blocks.y > 65536 || a.blocks.z > 65536)
        throw std::runtime_error("activity blocks out of range");
    const std::size_t total = static_cast<std::size_t>(a.blocks.x) * static_cast<std::size_t>(a.blocks.y) * static_cast<std::size_t>(a.blocks.z);
    for (const json& r : field(j, "runs")) {
        const auto n = r.at(1).get<std::uint64_t>();
        if (n == 0 || n > total - a.stamps.size()) throw std::runtime_error("activity runs do not cover its blocks");
        a.stamps.insert(a.stamps.end(), n, r.at(0).get<std::int64_t>());
    }
    if (a.stamps.size() != total) throw std::runtime_error("activity runs do not cover its blocks");
    return a;
}

Workspace parse_workspace(const json& j) {
    if (!j.is_object() || !j.contains("liveset_workspace")) throw std::runtime_error("not a liveset workspace (no 'liveset_workspace' version)");
    const int version = static_cast<int>(number(j, "liveset_workspace"));
    if (version != kWorkspaceVersion)
        throw std::runtime_error(fmt::format("workspace version {}; this liveset reads version {}", version, kWorkspaceVersion));
    Workspace ws;
    ws.image = field(j, "image").get<std::string>();
    ws.roi = field(j, "roi").get<std::string>();
    if (ws.roi.empty()) ws.roi = "none";  // older workspaces saved "" without a ROI (now the default: auto on a head)
    if (j.contains("bias_corrected")) {
        if (!j["bias_corrected"].is_boolean()) throw std::runtime_error("field 'bias_corrected' is not true or false");
        ws.bias_corrected = j["bias_corrected"].get<bool>();
    }
    const json& g = field(j, "geometry");
    const auto d = numbers(g, "dims", 3), dir = numbers(g, "direction", 9);
    Mat3d direction{};
    std::copy(dir.begin(), dir.end(), direction.begin());
    try {
        ws.lattice = Lattice({static_cast<int>(d[0]), static_cast<int>(d[1]), static_cast<int>(d[2])}, vec3(g, "spacing"), vec3(g, "origin"), direction);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("bad geometry: ") + e.what());
    }
    ws.image_checksum = field(j, "image_fnv").get<std::uint64_t>();
    if (j.contains("roi_fnv")) {  // absent in older files: nothing recorded; null: saved without a ROI
        ws.roi_recorded = true;
        if (!j["roi_fnv"].is_null()) ws.roi_checksum = field(j, "roi_fnv").get<std::uint64_t>();
    }
    if (!field(j, "seeds").is_array()) throw std::runtime_error("field 'seeds' is not a list");
    for (const json& s : field(j, "seeds")) {
        if (!s.is_array() || s.size() != 4) throw std::runtime_error("a seed is not [i, j, k, radius]");
        ws.marks.seeds.push_back({{s[0].get<double>(), s[1].get<double>(), s[2].get<double>()}, s[3].get<double>()});
    }
    const json& p = field(j, "params");
    ws.marks.params = {number(p, "mu"), number(p, "epsilon"), number(p, "n"), number(p, "alpha")};
    // Absent in workspaces written before the pre-smoothing: they ran without it.
    if (p.contains("smooth_mm")) ws.marks.params.smooth_mm = number(p, "smooth_mm");
    ws.marks.window_from_seeds = field(p, "window_from_seeds").get<bool>();
    // Absent in workspaces written before the automatic α: their α was set by hand.
    ws.marks.alpha_automatic = p.contains("alpha_automatic") && field(p, "alpha_automatic").get<bool>();
    ws.marks.iterations = static_cast<int>(number(j, "iterations"));
    ws.thin_fronts = false;  // a workspace written before session 72 records no step: the rule was off
    if (j.contains("step")) {
        const json& st = j["step"];
        const std::string kind = field(st, "kind").get<std::string>();
        if (kind != "sleeping" && kind != "exact") throw std::runtime_error(fmt::format("step kind '{}' is neither sleeping nor exact", kind));
        if (!field(st, "thin_fronts").is_boolean()) throw std::runtime_error("field 'thin_fronts' is not true or false");
        ws.step = kind;
        ws.thin_fronts = st["thin_fronts"].get<bool>();
        if (st.contains("coarse_start")) {  // absent in files written before session 82
            const json& c = st["coarse_start"];
            try {
                if (!c.is_string()) throw std::invalid_argument("not a name");
                ws.coarse_start = parse_coarse_start(c.get<std::string>());
            } catch (const std::invalid_argument&) {
                throw std::runtime_error(fmt::format("field 'coarse_start' is {}, not \"auto\", \"on\" or \"off\"", c.dump()));
            }
        }
    }
    ws.marks.pristine = false;
    ws.repair = swarm_from(field(j, "swarm"), ws.repair);
    if (!field(j, "target").is_null()) ws.target = vec3(j, "target");
    const json& v = field(j, "view");
    const json& c = field(v, "camera");
    const Vec3d pan = vec3(c, "pan");
    ws.view.camera = {number(c, "yaw"), number(c, "pitch"), number(c, "zoom"), glm::dvec3(pan.x, pan.y, pan.z)};
    const Vec3d cursor = vec3(v, "cursor");
    ws.view.cursor = {static_cast<int>(cursor.x), static_cast<int>(cursor.y), static_cast<int>(cursor.z)};
    ws.activity = activity_from(field(j, "activity"));
    return ws;
}

// How the ROI the workspace is opened with (`roi`, given as `source`: a path or "auto") differs
// from the one it was saved with; empty when it does not, or when nothing was recorded.
std::string roi_change(const Workspace& ws, const Grid<std::uint8_t>* roi, const std::string& source) {
    if (!ws.roi_recorded) return {};
    if (roi ? ws.roi_checksum && mask_checksum(*roi) == *ws.roi_checksum : !ws.roi_checksum) return {};
    if (!roi) return "opened without one";
    std::size_t voxels = 0;
    for (std::uint8_t v : roi->values()) voxels += v != 0;
    const auto name = [](const std::string& r) { return r == "auto" ? std::string("the automatic brain mask") : r; };
    const std::string now = name(source == "auto" ? source : fs::absolute(source).string());
    if (!ws.roi_checksum) return fmt::format("saved without one, opened with {} of {} voxels", now, voxels);
    if (now != name(ws.roi)) return fmt::format("saved with {}, opened with {} of {} voxels", name(ws.roi), now, voxels);
    return source == "auto" ? fmt::format("the automatic brain mask computed again has {} voxels", voxels)
                            : fmt::format("{} has {} voxels now", now, voxels);
}

}  // namespace

std::uint64_t image_checksum(const Grid<float>& image) {
    recovery_format::Fnv h;
    for (std::size_t i = 0; i < image.size(); ++i) {
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(image[static_cast<PointIndex>(i)]);
        h.add(&bits, sizeof bits);
    }
    return h.h;
}

fs::path workspace_state_path(const fs::path& workspace) { return fs::path(workspace.string() + ".state"); }

void save_workspace(const fs::path& path, const Session& session, const std::string& image, const std::string& roi,
                    bool bias_corrected, const WorkspaceView& view) {
    const SessionMarks& m = session.marks();
    const auto now = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    const std::optional<std::uint64_t> roi_fnv = session.roi() ? std::optional(mask_checksum(*session.roi())) : std::nullopt;
    const std::vector<std::uint8_t> state = encode_recovery(
        RecoveryView(image, 0, static_cast<std::int64_t>(now), m, roi_fnv, recorded_step(session.options().segmentation.step),
                     session.options().coarse_start, session.field().phi(),
                     session.field().status()));  // the JSON's "step" and "coarse_start" are the ones read back
    const Lattice& l = session.lattice();
    json seeds = json::array();
    for (const SeedBall& s : m.seeds) seeds.push_back({s.center.x, s.center.y, s.center.z, s.radius});
    json j{{"liveset_workspace", kWorkspaceVersion},
           {"image", image.empty() ? std::string() : fs::absolute(image).string()},
           {"roi", roi.empty() || roi == "auto" || roi == "none" ? roi : fs::absolute(roi).string()},  // "auto": computed again on reading
           {"bias_corrected", bias_corrected},
           {"geometry", {{"dims", {l.dims().x, l.dims().y, l.dims().z}}, {"spacing", vec(l.spacing())}, {"origin", vec(l.origin())},
                         {"direction", l.direction()}}},
           {"image_fnv", image_checksum(session.image())},
           {"roi_fnv", roi_fnv ? json(*roi_fnv) : json(nullptr)},
           {"state", {{"file", workspace_state_path(path).filename().string()}, {"fnv", trailing_checksum(state)}}},
           {"seeds", seeds},
           {"params", {{"mu", m.params.mu}, {"epsilon", m.params.epsilon}, {"n", m.params.n}, {"alpha", m.params.alpha},
                       {"smooth_mm", m.params.smooth_mm}, {"window_from_seeds", m.window_from_seeds}, {"alpha_automatic", m.alpha_automatic},
                       {"mu_raw", session.scale().to_raw(m.params.mu)}, {"epsilon_raw", session.scale().raw_length(m.params.epsilon)}}},
           {"iterations", m.iterations},
           {"step", {{"kind", step_name(session.options().segmentation.step)}, {"thin_fronts", session.options().segmentation.step.thin_fronts},
                     {"coarse_start", to_string(session.options().coarse_start)}}},
           {"activity", activity_json(session.activity_snapshot())},
           {"swarm", swarm_json(session.repair_options())},
           {"target", session.target() ? vec(*session.target()) : json(nullptr)},
           {"view", {{"camera", {{"yaw", view.camera.yaw_deg}, {"pitch", view.camera.pitch_deg}, {"zoom", view.camera.zoom},
                                 {"pan", {view.camera.pan.x, view.camera.pan.y, view.camera.pan.z}}}},
                     {"cursor", {view.cursor.x, view.cursor.y, view.cursor.z}}}}};
    try {
        write_file_atomically(workspace_state_path(path), std::string_view(reinterpret_cast<const char*>(state.data()), state.size()));
        write_file_atomically(path, j.dump(2) + "\n");
    } catch (const std::exception& e) {
        throw std::runtime_error(fmt::format("cannot write the workspace {}: {}", path.string(), e.what()));
    }
}

Workspace read_workspace(const fs::path& path) {
    Workspace ws;
    std::uint64_t state_fnv = 0;
    try {
        const std::string text = read_text(path);
        json j;
        try {
            j = json::parse(text);
        } catch (const json::parse_error& e) {
            throw std::runtime_error(fmt::format("not a liveset workspace: invalid or truncated JSON (byte {})", e.byte));
        }
        ws = parse_workspace(j);
        state_fnv = field(field(j, "state"), "fnv").get<std::uint64_t>();
    } catch (const json::exception& e) {  // a field of the wrong type
        throw std::runtime_error(fmt::format("workspace {}: a field has the wrong type ({})", path.string(), e.what()));
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(fmt::format("workspace {}: {}", path.string(), e.what()));
    }
    const fs::path state_path = workspace_state_path(path);
    RecoveryState state;
    try {
        state = read_recovery(state_path);
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(fmt::format("workspace {}: its level set {}", path.string(), e.what()));
    }
    std::vector<std::uint8_t> tail(8);
    std::ifstream in(state_path, std::ios::binary);
    in.seekg(-8, std::ios::end);
    in.read(reinterpret_cast<char*>(tail.data()), 8);
    if (!in || trailing_checksum(tail) != state_fnv)
        throw std::runtime_error(fmt::format("workspace {}: {} belongs to another save (its checksum differs)", path.string(), state_path.string()));
    if (!state.phi.lattice().same_geometry(ws.lattice, 1e-6))
        throw std::runtime_error(fmt::format("workspace {}: its level set ({}) does not match its image ({})", path.string(),
                                             state.phi.lattice().describe(), ws.lattice.describe()));
    ws.phi = std::move(state.phi);
    ws.status = std::move(state.status);
    return ws;
}

void check_workspace_image(const Workspace& ws, const fs::path& path, const Grid<float>& image, const Grid<std::uint8_t>* roi,
                           const std::string& roi_source) {
    if (!image.lattice().same_geometry(ws.lattice, 1e-6))
        throw std::runtime_error(fmt::format("workspace {} was saved for another image: {} there, {} here (size, spacing, origin or direction)",
                                             path.string(), ws.lattice.describe(), image.lattice().describe()));
    if (image_checksum(image) == ws.image_checksum) return;
    if (const std::string change = roi_change(ws, roi, roi_source); ws.bias_corrected && !change.empty())
        throw std::runtime_error(fmt::format("workspace {}: its ROI is not the one it was saved with ({}), and N4 fitted in the ROI "
                                             "corrects the image otherwise", path.string(), change));
    throw std::runtime_error(fmt::format("workspace {} was saved for another image: same geometry, other voxel values (or another N4 correction of it)", path.string()));
}

std::string workspace_roi_warning(const Workspace& ws, const fs::path& path, const Session& session, const std::string& roi_source) {
    const std::string change = roi_change(ws, session.roi(), roi_source);
    if (change.empty()) return {};
    return fmt::format("workspace {}: its ROI is not the one it was saved with ({}): the level set continues as saved, but the "
                       "front may now move where it could not", path.string(), change);
}

void apply_workspace(Session& session, const Workspace& ws) {
    validate(ws.repair);
    if (!session.load_recovered(ws.phi, ws.status, ws.marks))
        throw std::invalid_argument("the workspace's level set is not a consistent sparse field");
    session.set_repair_options(ws.repair);
    if (ws.target) session.set_target(*ws.target);
    session.restore_activity(ws.activity);  // last: loading woke the points it wrote
}

}  // namespace liveset::viewer
