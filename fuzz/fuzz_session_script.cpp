// libFuzzer target: the viewer's session-script parser (`liveset view --script`), on a 64^3
// lattice. Every input must be accepted as a list of checked actions or refused with one
// cli::UsageError line naming the problem; anything else (crash, sanitizer report, another
// exception, a multi-line message) is a bug.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "cli_common.hpp"
#include "script.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const liveset::Lattice lattice({64, 64, 64}, {1.0, 1.2, 0.8});
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const liveset::viewer::Script script = liveset::viewer::parse_script_text(text, "fuzz.json", lattice);
        if (script.actions.size() > size) std::abort();  // every action comes from at least one byte
    } catch (const liveset::cli::UsageError& e) {
        const std::string message = e.what();
        if (message.empty()) std::abort();
    }
    return 0;
}
