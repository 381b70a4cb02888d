// The data check beside the read (image_io.cpp's read_checked): a float NIfTI whose size or gzip
// trailer says its data is all there is checked while ITK reads it, on another thread. Damage the
// trailer cannot see (a corrupt middle) must still be refused with the check's one message, NaN
// kept where the file holds them and infinite values refused, on one thread and on two; and the
// test that picks the overlap (nifti_float_data_complete) against files whose answer is known.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "liveset/io/file_checks.hpp"
#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;

class DataCheck : public ::testing::Test {
protected:
    void SetUp() override { dir_ = testing::scratch_dir("io_data_check"); }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

// 40^3 random floats: a gzip stream with little to compress, so its middle is voxel data.
Grid<float> noise_image() {
    Grid<float> g(Lattice({40, 40, 40}, {1.0, 1.0, 1.0}));
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 100.0f);
    for (PointIndex i = 0; i < g.size(); ++i) g[i] = u(rng);
    return g;
}

std::string bytes_of(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

// The message of read(), which must throw ImageIoError.
template <class Read>
std::string error_of(Read&& read) {
    try {
        read();
    } catch (const ImageIoError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST_F(DataCheck, FloatDataCompleteByTrailerOrSize) {
    const Grid<float> image = noise_image();
    write_image(image, path("f.nii.gz"));
    write_image(image, path("f.nii"));
    EXPECT_TRUE(io_detail::nifti_float_data_complete(path("f.nii.gz")));
    EXPECT_TRUE(io_detail::nifti_float_data_complete(path("f.nii")));
    write_label_image(Grid<std::uint8_t>(image.lattice(), 1), path("u8.nii.gz"));  // not float: the check reads no value
    EXPECT_FALSE(io_detail::nifti_float_data_complete(path("u8.nii.gz")));
    write_image(image, path("f.mha"));  // not NIfTI
    EXPECT_FALSE(io_detail::nifti_float_data_complete(path("f.mha")));
    for (const std::string name : {"f.nii.gz", "f.nii"}) {
        const std::string bytes = bytes_of(path(name));
        write_bytes(path("cut_" + name), bytes.substr(0, bytes.size() - 100));
        EXPECT_FALSE(io_detail::nifti_float_data_complete(path("cut_" + name))) << name;
    }
    EXPECT_FALSE(io_detail::nifti_float_data_complete(path("missing.nii.gz")));
}

TEST_F(DataCheck, DamageBehindAnIntactTrailerIsStillRefused) {
    const Grid<float> image = noise_image();
    write_image(image, path("f.nii.gz"));
    std::string bytes = bytes_of(path("f.nii.gz"));
    for (std::size_t k = bytes.size() / 2; k < bytes.size() / 2 + 64; ++k) bytes[k] = static_cast<char>(bytes[k] ^ 0x5a);
    write_bytes(path("bad.nii.gz"), bytes);
    ASSERT_TRUE(io_detail::nifti_float_data_complete(path("bad.nii.gz")));  // the trailer cannot tell
    // Cut in the middle, its trailer kept: a stream that ends early, read by both at once.
    const std::string whole = bytes_of(path("f.nii.gz"));
    write_bytes(path("cut.nii.gz"), whole.substr(0, whole.size() / 2) + whole.substr(whole.size() - 8));
    ASSERT_TRUE(io_detail::nifti_float_data_complete(path("cut.nii.gz")));
    for (const std::size_t threads : {1u, 2u})
        for (const std::string name : {"bad.nii.gz", "cut.nii.gz"}) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            ::testing::internal::CaptureStderr();
            const std::string e = error_of([&] { read_image(path(name)); });
            const std::string l = error_of([&] { read_label_image(path(name)); });
            EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << name;  // nothing printed by ITK's niftilib
            // The check's message (bytes held of those promised), not the read's.
            for (const std::string& m : {e, l}) {
                EXPECT_NE(m.find("file is corrupt or truncated (holds "), std::string::npos) << threads << " " << name << ": " << m;
                EXPECT_NE(m.find(" data bytes"), std::string::npos) << m;
                EXPECT_NE(m.find(name), std::string::npos) << m;
            }
        }
}

TEST_F(DataCheck, NanKeptAndInfinityRefusedBesideTheRead) {
    Grid<float> image = noise_image();
    image[123] = std::numeric_limits<float>::quiet_NaN();
    image[image.size() - 1] = std::numeric_limits<float>::quiet_NaN();  // in the last chunk streamed
    write_image(image, path("nan.nii.gz"));
    image[500] = -std::numeric_limits<float>::infinity();
    write_image(image, path("inf.nii.gz"));
    for (const std::size_t threads : {1u, 2u}) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        const Grid<float> back = read_image(path("nan.nii.gz"), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep);
        std::size_t nan = 0, same = 0;
        for (PointIndex i = 0; i < back.size(); ++i) {
            nan += std::isnan(back[i]) ? 1 : 0;
            same += (std::isnan(image[i]) ? std::isnan(back[i]) : back[i] == image[i]) ? 1 : 0;
        }
        EXPECT_EQ(nan, 2u) << threads;
        EXPECT_EQ(same, back.size() - 1) << threads;  // all but the voxel made infinite after writing nan.nii.gz
        EXPECT_NE(error_of([&] { read_image(path("nan.nii.gz")); }).find("2 voxels are NaN or infinite"), std::string::npos);
        EXPECT_NE(error_of([&] { read_image(path("inf.nii.gz"), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep); })
                      .find("1 voxel is infinite"),
                  std::string::npos);
    }
}

}  // namespace
}  // namespace liveset
