// libFuzzer target: the viewer's recovery files (liveset/session/recovery.hpp), decoded from
// memory. An input is either a valid state (re-encoding it gives the same bytes; an older file gives
// them in today's version 6: the version field, the smoothing σ 0 inserted after α (versions 1, 2),
// "no ROI" (a zero flag and checksum) inserted before the voxel count (versions 1-3), the default
// step (sleeping, the thin-front rule on: 1, 1) inserted before the voxel count (versions 1-4), the
// default coarse start (auto: 0) inserted before the voxel count (versions 1-5), and the checksum
// differ) or refused with std::runtime_error; anything else is a bug.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "liveset/session/recovery.hpp"

namespace {

// Today's encoding of an older file `data` (already decoded, so its fields are in bounds): the same
// bytes with the version set to 6, eight zero bytes (σ = 0.0) after the four parameters (versions
// 1, 2), nine zero bytes (no ROI) after the seeds (versions 1-3), then the default step's two bytes
// (versions 1-4) and the default coarse start's byte (versions 1-5), the checksum left out of the
// comparison.
bool older_file_reencoded(const std::uint8_t* data, std::size_t size, std::uint32_t version, const std::vector<std::uint8_t>& again) {
    std::vector<std::uint8_t> expected(data, data + size - 8);
    const std::uint32_t today = 6;
    std::memcpy(expected.data() + 8, &today, sizeof today);
    std::uint32_t path = 0;
    std::memcpy(&path, data + 24, sizeof path);  // magic, version, signal, time, then the path's length
    const std::size_t sigma = 28 + std::size_t{path} + 12 + 15 * 8 + 4 * 8;  // path, dims, geometry, µ ε n α
    if (version < 3) expected.insert(expected.begin() + static_cast<std::ptrdiff_t>(sigma), 8, 0);
    const std::size_t seeds_at = sigma + 8 + 1 + 4;  // σ, flags, iterations
    if (seeds_at + 4 > expected.size()) return false;
    std::uint32_t seeds = 0;
    std::memcpy(&seeds, expected.data() + seeds_at, sizeof seeds);
    const std::size_t roi_at = seeds_at + 4 + 32 * std::size_t{seeds};
    if (roi_at > expected.size()) return false;
    if (version < 4) expected.insert(expected.begin() + static_cast<std::ptrdiff_t>(roi_at), 9, 0);
    if (version < 5) expected.insert(expected.begin() + static_cast<std::ptrdiff_t>(roi_at + 9), 2, 1);  // sleeping, the rule on
    expected.insert(expected.begin() + static_cast<std::ptrdiff_t>(roi_at + 11), 1, 0);  // the coarse start auto
    return again.size() == expected.size() + 8 && std::memcmp(again.data(), expected.data(), expected.size()) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const liveset::RecoveryState state = liveset::decode_recovery(data, size);
        const std::vector<std::uint8_t> again = liveset::encode_recovery(state);
        std::uint32_t version = 0;
        std::memcpy(&version, data + 8, sizeof version);  // after the 8-byte magic (a valid file is longer)
        if (version < 6) {
            if (!older_file_reencoded(data, size, version, again)) std::abort();
            const liveset::RecoveryState back = liveset::decode_recovery(again.data(), again.size());
            if (liveset::encode_recovery(back) != again) std::abort();
        } else if (again.size() != size || std::memcmp(again.data(), data, size) != 0) {
            std::abort();
        }
    } catch (const std::runtime_error&) {
    }
    return 0;
}
