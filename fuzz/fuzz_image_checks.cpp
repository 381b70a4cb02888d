// libFuzzer target: the project's own byte-level image checks (liveset_io's file_checks: NIfTI-1/-2
// headers and data size, gzip streams and trailers, NaN counting and flagging; MetaImage headers and their data files).
// The first input byte picks the check; the rest is the file. The checks must answer (possibly
// "truncated") or throw std::runtime_error, never crash or read out of bounds.
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "fuzz_input_file.hpp"
#include "liveset/io/file_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* const kExtensions[] = {".nii", ".nii.gz", ".mha", ".mhd"};
    const int which = data[0] % 4;
    const liveset::fuzz::InputFile file(data + 1, size - 1, kExtensions[which]);
    try {
        std::vector<std::uint8_t> nan_at;  // where the NaN lie, as read_image keeps a scan's
        if (which < 2) {
            (void)liveset::io_detail::nifti_float_data_complete(file.path().string());
            (void)liveset::io_detail::check_nifti_data(file.path().string(), true, data[0] & 4 ? &nan_at : nullptr);
        } else {
            (void)liveset::io_detail::check_metaimage_data(file.path().string(), 4096);
        }
    } catch (const std::runtime_error&) {
    }
    return 0;
}
