// The one atomic file writer: every output of liveset (images, meshes, PNGs, reports, recovery
// files) is written to a hidden temporary next to its target, flushed to disk and renamed into
// place, so a reader never sees a half-written file and a failure leaves nothing behind.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>

namespace liveset {

// ".nii.gz" for "a.nii.gz", ".mha" for "a.mha", "" when the name has no extension.
std::string file_extension(const std::string& filename);
// file_extension lower-cased (".nii.gz" for "A.NII.GZ"), for choosing a format by name.
std::string lowercase_extension(const std::string& filename);

// One atomic output. The temporary keeps the target's extension (so format-by-extension writers
// pick the same format): "dir/seg.nii.gz" is written as "dir/.seg.tmp-<pid>-<n>.nii.gz". A writer
// may add companion files with the same temporary stem (".seg.tmp-<pid>-<n>.raw" next to a .mhd
// header). commit() flushes them to disk and renames them to their final names, companions first
// and the file itself last (the commit point); a text header's references to the temporary stem
// are rewritten first. Until commit() succeeds, the destructor removes every temporary.
// Failures throw std::runtime_error with a short reason that does not repeat the target's path.
class AtomicFile {
public:
    explicit AtomicFile(const std::filesystem::path& target);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::filesystem::path& target() const { return target_; }
    const std::filesystem::path& temp_path() const { return temp_; }
    // Creates the (empty) temporary, so that a folder we may not write to is reported with the
    // system's reason ("cannot create a file in folder "x" (Permission denied)").
    void create();
    void commit(bool text_header = false);

private:
    std::filesystem::path target_, dir_, temp_;
    std::string stem_, temp_stem_;
    bool committed_ = false;
    int slot_ = -1;  // in the registry of temporaries being written (see discard_temporaries)
};

// Writes `target` atomically with what `write` puts into the stream (binary mode). A stream error
// ("write error (disk full?)") or an exception from `write` removes the temporary and throws.
void write_file_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write);
void write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

// For a fatal-signal handler: removes the temporaries of the AtomicFiles alive in this process (a
// write the signal interrupted), so that even a process that dies leaves no half-written file
// behind. Async-signal-safe (unlink only). Companion files of a multi-file image are not covered.
void discard_temporaries() noexcept;

// For async-signal context only (the crash recovery handler, which cannot allocate): the temporary
// it writes by hand for `target` ("dir/.name.crash-<pid>" + extension), and the rename into place
// (0, or the errno). Every other caller uses AtomicFile.
std::filesystem::path signal_temp_path(const std::filesystem::path& target);
int rename_into_place(const char* temp, const char* target) noexcept;

}  // namespace liveset
