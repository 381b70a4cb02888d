// libFuzzer target: the viewer's recovery files (liveset/session/recovery.hpp), decoded from
// memory. An input is either a valid state (re-encoding it gives the same bytes) or refused with
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
        if (again.size() != size || std::memcmp(again.data(), data, size) != 0) std::abort();
    } catch (const std::runtime_error&) {
    }
    return 0;
}
