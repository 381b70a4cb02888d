// Internal to liveset_io: replaces an output file atomically through a hidden temporary next to
// it. No ITK in here.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace liveset::io_detail {

// ".nii.gz" for "a.nii.gz", ".mha" for "a.mha", "" when the name has no extension.
std::string extension_of(const std::string& filename);

// The temporary keeps the target's extension (so writers pick the same format):
// "dir/seg.nii.gz" is written as "dir/.seg.tmp-<pid>-<n>.nii.gz". A writer may add companion
// files with the same temporary stem (".seg.tmp-<pid>-<n>.raw" next to a .mhd / .nhdr header).
// commit() flushes them to disk and renames them to the final names, companions first and the
// file itself last (the commit point); a text header's references to the temporary stem are
// rewritten first. Until commit() succeeds, the destructor removes every temporary.
class AtomicOutput {
public:
    explicit AtomicOutput(const std::filesystem::path& target);
    ~AtomicOutput();
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::filesystem::path& temp_path() const { return temp_; }
    // Creates the (empty) temporary, so that a folder we may not write to is reported with the
    // system's reason ("cannot create a file in folder "x" (Permission denied)").
    void create();
    // Throws std::runtime_error (a short reason, without the path) when a step fails.
    void commit(bool text_header);

private:
    std::filesystem::path target_, dir_, temp_;
    std::string stem_, temp_stem_;
    bool committed_ = false;
};

}  // namespace liveset::io_detail
