// libFuzzer target: the viewer's recovery files (liveset/session/recovery.hpp), decoded from
// memory. An input is either a valid state (re-encoding it gives the same bytes; a version-1 file
// gives them in version 2: the same bytes but the version and the checksum) or refused with
// std::runtime_error; anything else is a bug.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "liveset/session/recovery.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const liveset::RecoveryState state = liveset::decode_recovery(data, size);
        const std::vector<std::uint8_t> again = liveset::encode_recovery(state);
        if (again.size() != size) std::abort();
        std::uint32_t version = 0;
        std::memcpy(&version, data + 8, sizeof version);  // after the 8-byte magic (a valid file is longer)
        if (version == 1) {
            // Today's encoding of an older file: the version field and the trailing checksum differ,
            // and it decodes to the same state (re-encoding it again gives the same bytes).
            const std::size_t body = 12, tail = size - 8;
            if (std::memcmp(again.data(), data, 8) != 0 || std::memcmp(again.data() + body, data + body, tail - body) != 0) std::abort();
            const liveset::RecoveryState back = liveset::decode_recovery(again.data(), again.size());
            if (liveset::encode_recovery(back) != again) std::abort();
        } else if (std::memcmp(again.data(), data, size) != 0) {
            std::abort();
        }
    } catch (const std::runtime_error&) {
    }
    return 0;
}
