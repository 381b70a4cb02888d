// libFuzzer target: the viewer's recovery files (liveset/session/recovery.hpp), decoded from
// memory. An input is either a valid state (re-encoding it gives the same bytes; a version-1 or -2
// file gives them in version 3: the version field, the smoothing σ 0 inserted after α, and the
// checksum differ) or refused with std::runtime_error; anything else is a bug.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "liveset/session/recovery.hpp"

namespace {

// Today's encoding `again` of an older file `data`: the same bytes but the version field, eight
// zero bytes (σ = 0.0) after the four parameters, and the trailing checksum.
bool older_file_reencoded(const std::uint8_t* data, std::size_t size, const std::vector<std::uint8_t>& again) {
    if (again.size() != size + 8) return false;
    std::uint32_t path = 0;
    std::memcpy(&path, data + 24, sizeof path);  // magic, version, signal, time, then the path's length
    const std::size_t sigma = 28 + std::size_t{path} + 12 + 15 * 8 + 4 * 8;  // path, dims, geometry, µ ε n α
    if (sigma + 8 > size) return false;
    const std::uint8_t zero[8] = {};
    return std::memcmp(again.data(), data, 8) == 0 && std::memcmp(again.data() + 12, data + 12, sigma - 12) == 0 &&
           std::memcmp(again.data() + sigma, zero, 8) == 0 && std::memcmp(again.data() + sigma + 8, data + sigma, size - 8 - sigma) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const liveset::RecoveryState state = liveset::decode_recovery(data, size);
        const std::vector<std::uint8_t> again = liveset::encode_recovery(state);
        std::uint32_t version = 0;
        std::memcpy(&version, data + 8, sizeof version);  // after the 8-byte magic (a valid file is longer)
        if (version < 3) {
            if (!older_file_reencoded(data, size, again)) std::abort();
            const liveset::RecoveryState back = liveset::decode_recovery(again.data(), again.size());
            if (liveset::encode_recovery(back) != again) std::abort();
        } else if (again.size() != size || std::memcmp(again.data(), data, size) != 0) {
            std::abort();
        }
    } catch (const std::runtime_error&) {
    }
    return 0;
}
