// libFuzzer target: the project's own mesh readers (PLY binary/ASCII, OBJ, STL binary/ASCII).
// The first input byte picks the format; the rest is the file. A reader may refuse the input with
// std::runtime_error / std::invalid_argument; anything else (crash, sanitizer report, another
// exception, a mesh whose indices point outside its vertices) is a bug.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_input_file.hpp"
#include "liveset/mesh/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* const kExtensions[] = {".ply", ".obj", ".stl"};
    const liveset::fuzz::InputFile file(data + 1, size - 1, kExtensions[data[0] % 3]);
    try {
        const liveset::Mesh mesh = liveset::read_mesh(file.path());
        if (mesh.indices.size() % 3 != 0) std::abort();
        for (std::uint32_t i : mesh.indices)
            if (i >= mesh.vertices.size()) std::abort();
    } catch (const std::runtime_error&) {
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
