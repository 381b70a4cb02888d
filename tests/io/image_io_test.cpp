// Image IO tests: round trips through every supported format with oblique, anisotropic geometry,
// DICOM series written by ITK's GDCM writer, every refusal (each with the path and a specific
// phrase), atomic writes that leave no temporaries behind, and the BrainWeb data when present.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <zlib.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "dicom_writer.hpp"
#include "liveset/io/image_io.hpp"
#include "io/minc_tools.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;
using testing::rotation;

// A fresh folder per test, removed afterwards.
class ImageIo : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = info->name();  // "Case/param" for parameterised tests
        for (char& c : name) c = (c == '/') ? '_' : c;
        dir_ = testing::scratch_dir("io_" + name);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::set<std::string> listing(const fs::path& folder) const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(folder)) names.insert(e.path().filename().string());
        return names;
    }
    std::set<std::string> listing() const { return listing(dir_); }

    fs::path dir_;
};


Lattice test_lattice() {
    return Lattice({7, 9, 11}, {0.7, 1.3, 2.1}, {-12.5, 30.25, 4.0}, rotation({1, 2, 3}, 25));
}

Grid<float> test_image() {
    Grid<float> g(test_lattice());
    for (PointIndex i = 0; i < g.size(); ++i) {
        const Vec3i p = g.lattice().coord(i);
        g[i] = 0.5f * float(p.x) - 1.25f * float(p.y) + 3.1f * float(p.z) + 0.01f * float(p.x * p.y * p.z) - 7.0f;
    }
    return g;
}

Grid<std::uint8_t> test_labels() {
    Grid<std::uint8_t> g(test_lattice());
    for (PointIndex i = 0; i < g.size(); ++i) g[i] = static_cast<std::uint8_t>((i * 37u) % 256u);
    return g;
}

void expect_same_geometry(const Lattice& a, const Lattice& b, double tol = 1e-4) {
    EXPECT_EQ(a.dims(), b.dims());
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.spacing()[k], b.spacing()[k], tol) << "spacing axis " << k;
        EXPECT_NEAR(a.origin()[k], b.origin()[k], tol) << "origin axis " << k;
    }
    for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(a.direction()[k], b.direction()[k], tol) << "direction " << k;
}

// Runs f, expects ImageIoError whose one-line message holds `path` and `phrase`; returns it.
template <class F>
std::string expect_error(F&& f, const std::string& path, const std::string& phrase) {
    try {
        f();
    } catch (const ImageIoError& e) {
        const std::string msg = e.what();
        if (std::getenv("LIVESET_IO_TEST_PRINT")) std::cout << "  message: " << msg << "\n";
        EXPECT_NE(msg.find(path), std::string::npos) << "message lacks the path: " << msg;
        EXPECT_NE(msg.find(phrase), std::string::npos) << "message lacks \"" << phrase << "\": " << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
        return msg;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected ImageIoError, got another exception: " << e.what();
        return {};
    }
    ADD_FAILURE() << "expected ImageIoError (\"" << phrase << "\") for " << path;
    return {};
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// A hand-written MetaImage with the data inline (ElementDataFile = LOCAL).
void write_mha(const std::string& path, const std::string& header_lines, const void* data, std::size_t bytes) {
    std::ofstream out(path, std::ios::binary);
    out << "ObjectType = Image\n" << header_lines << "ElementDataFile = LOCAL\n";
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
}

// ---------------------------------------------------------------------------------------------
// Round trips

class RoundTrip : public ImageIo, public ::testing::WithParamInterface<const char*> {};

TEST_P(RoundTrip, FloatImageKeepsValuesAndObliqueGeometry) {
    const std::string ext = GetParam();
    const Grid<float> image = test_image();
    const std::string file = path("image" + ext);
    write_image(image, file);
    const Grid<float> back = read_image(file);
    expect_same_geometry(image.lattice(), back.lattice());
    ASSERT_EQ(back.size(), image.size());
    for (PointIndex i = 0; i < image.size(); ++i) ASSERT_NEAR(back[i], image[i], 1e-5f * (1 + std::abs(image[i]))) << i;

    const ImageHeader h = read_image_header(file);
    EXPECT_EQ(h.dims, (Vec3i{7, 9, 11}));
    EXPECT_EQ(h.dimension, 3);
    EXPECT_EQ(h.components, 1);
    EXPECT_EQ(h.pixel_type, "float");
    EXPECT_FALSE(h.format.empty());
    for (const auto& name : listing()) EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << name;
}

TEST_P(RoundTrip, LabelImageIsExact) {
    const std::string ext = GetParam();
    const Grid<std::uint8_t> labels = test_labels();
    const std::string file = path("labels" + ext);
    write_label_image(labels, file);
    const Grid<std::uint8_t> back = read_label_image(file);
    expect_same_geometry(labels.lattice(), back.lattice());
    ASSERT_EQ(back.size(), labels.size());
    for (PointIndex i = 0; i < labels.size(); ++i) ASSERT_EQ(back[i], labels[i]) << i;
    EXPECT_EQ(read_image_header(file).pixel_type, "unsigned_char");
    // Labels also read as a float image (e.g. a mask used as a speed image).
    const Grid<float> as_float = read_image(file);
    for (PointIndex i = 0; i < labels.size(); ++i) ASSERT_EQ(as_float[i], float(labels[i])) << i;
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip,
                         ::testing::Values(".nii", ".nii.gz", ".mha", ".mhd", ".nrrd", ".nhdr", ".mnc", ".mgz", ".mgh", ".mgh.gz"),
                         [](const auto& info) {
                             std::string n = info.param + 1;
                             for (char& c : n) c = (c == '.') ? '_' : c;
                             return n;
                         });

TEST_F(ImageIo, HeaderNamesTheFormat) {
    const Grid<float> image = test_image();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"a.nii.gz", "NIfTI"}, {"a.mha", "MetaImage"}, {"a.nrrd", "NRRD"}, {"a.mnc", "MINC"}};
    for (const auto& [name, format] : cases) {
        write_image(image, path(name));
        EXPECT_EQ(read_image_header(path(name)).format, format) << name;
    }
}

// Independent of ITK's reader: the NIfTI sform must be the RAS form of our LPS geometry, which is
// what FSLeyes, 3D Slicer and ITK-SNAP display.
TEST_F(ImageIo, NiftiSformIsRasOfTheLpsGeometry) {
    const Grid<float> image = test_image();
    write_image(image, path("g.nii"));
    std::ifstream in(path("g.nii"), std::ios::binary);
    char h[348];
    ASSERT_TRUE(in.read(h, sizeof h));
    std::int16_t sform_code;
    std::memcpy(&sform_code, h + 254, 2);
    EXPECT_GT(sform_code, 0);
    float srow[3][4];
    std::memcpy(srow, h + 280, sizeof srow);
    const Lattice& l = image.lattice();
    for (int r = 0; r < 3; ++r) {
        const double flip = r < 2 ? -1.0 : 1.0;  // LPS -> RAS
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(srow[r][c], flip * l.direction()[std::size_t(r * 3 + c)] * l.spacing()[c], 1e-5) << r << c;
        EXPECT_NEAR(srow[r][3], flip * l.origin()[r], 1e-4) << r;
    }
}

// A NIfTI whose qform and sform codes are both 0 (NIFTI_XFORM_UNKNOWN; an Analyze file likewise)
// carries no orientation: ITK reads its axes as LPS identity, and the header says they are not known.
// Every header liveset writes, and the other formats, give one.
TEST_F(ImageIo, AHeaderWithoutOrientationSaysSo) {
    const Grid<float> image = test_image();
    for (const std::string name : {"o.nii", "o.nii.gz", "o.mha", "o.nrrd", "o.mnc"}) {
        write_image(image, path(name));
        EXPECT_TRUE(read_image_header(path(name)).orientation_known) << name;
    }
    {
        std::fstream f(path("o.nii"), std::ios::in | std::ios::out | std::ios::binary);
        const std::int16_t zero = 0;
        f.seekp(252);
        f.write(reinterpret_cast<const char*>(&zero), 2);  // qform_code
        f.write(reinterpret_cast<const char*>(&zero), 2);  // sform_code
    }
    ImageHeader h;
    const Grid<float> read = read_image(path("o.nii"), kDefaultImageMemoryLimit, &h);
    EXPECT_FALSE(h.orientation_known);
    EXPECT_FALSE(read_image_header(path("o.nii")).orientation_known);
    EXPECT_EQ(read.lattice().direction(), kIdentity3);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(read.lattice().spacing()[a], image.lattice().spacing()[a], 1e-6) << a;
    ASSERT_EQ(read.size(), image.size());
    for (std::size_t i = 0; i < read.size(); ++i) ASSERT_EQ(read[static_cast<PointIndex>(i)], image[static_cast<PointIndex>(i)]) << i;

    // The same voxels as an Analyze 7.5 pair (the NIfTI header without its magic, the data after
    // it): no orientation either, and read without ITK's deprecation warning on stderr.
    {
        std::ifstream in(path("o.nii"), std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), {});
        float vox_offset;
        std::memcpy(&vox_offset, bytes.data() + 108, 4);
        std::string hdr = bytes.substr(0, 348);
        std::fill(hdr.begin() + 344, hdr.end(), '\0');  // magic "n+1": gone
        const float zero = 0.0f;  // the data start the .img
        std::memcpy(hdr.data() + 108, &zero, 4);
        std::ofstream(path("o.hdr"), std::ios::binary) << hdr;
        std::ofstream(path("o.img"), std::ios::binary) << bytes.substr(static_cast<std::size_t>(vox_offset));
    }
    ::testing::internal::CaptureStderr();
    ImageHeader ah;
    const Grid<float> analyze = read_image(path("o.hdr"), kDefaultImageMemoryLimit, &ah);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    EXPECT_FALSE(ah.orientation_known);
    ASSERT_EQ(analyze.size(), image.size());
    for (std::size_t i = 0; i < analyze.size(); ++i) ASSERT_EQ(analyze[static_cast<PointIndex>(i)], image[static_cast<PointIndex>(i)]) << i;
}

// Written as without orientation (WriteOptions) on the lattice such a file reads as (the LPS
// identity at the origin): a NIfTI's qform and sform codes are 0 in the file (read raw, both byte
// positions), it reads back as not oriented with the same voxels and lattice; its other header
// bytes are ITK's. A lattice placed otherwise keeps its codes and placement (codes 0 would lose
// it). Other formats take no such mark: they read back oriented.
TEST_F(ImageIo, AnImageWithoutOrientationIsWrittenAsOne) {
    const Grid<float> oblique = test_image();
    Grid<float> image(Lattice(oblique.dims(), oblique.lattice().spacing()));
    std::copy(oblique.values().begin(), oblique.values().end(), image.values().begin());
    for (const std::string name : {"u.nii", "u.nii.gz"}) {
        write_image(image, path("k" + name));
        write_image(image, path(name), {.orientation_known = false});
        const auto header_bytes = [&](const std::string& file) {
            gzFile f = gzopen(path(file).c_str(), "rb");
            std::string h(348, '\0');
            EXPECT_EQ(gzread(f, h.data(), 348), 348) << file;
            gzclose(f);
            return h;
        };
        const std::string known = header_bytes("k" + name), unknown = header_bytes(name);
        EXPECT_NE(known.substr(252, 4), std::string(4, '\0')) << name;
        EXPECT_EQ(unknown.substr(252, 4), std::string(4, '\0')) << name;
        EXPECT_EQ(known.substr(0, 252), unknown.substr(0, 252)) << name;
        EXPECT_EQ(known.substr(256), unknown.substr(256)) << name;
        ImageHeader h;
        const Grid<float> read = read_image(path(name), kDefaultImageMemoryLimit, &h);
        EXPECT_FALSE(h.orientation_known) << name;
        expect_same_geometry(read.lattice(), image.lattice(), 1e-6);
        ASSERT_EQ(read.size(), image.size());
        for (std::size_t i = 0; i < read.size(); ++i) ASSERT_EQ(read[static_cast<PointIndex>(i)], image[static_cast<PointIndex>(i)]) << i;
    }
    Grid<std::uint8_t> labels(image.lattice(), 0);
    labels[PointIndex{5}] = 1;
    write_label_image(labels, path("l.nii.gz"), {.orientation_known = false});
    ImageHeader lh;
    EXPECT_EQ(read_label_image(path("l.nii.gz"), kDefaultImageMemoryLimit, &lh)[PointIndex{5}], 1);
    EXPECT_FALSE(lh.orientation_known);
    for (const std::string name : {"u.mha", "u.nrrd"}) {
        write_image(image, path(name), {.orientation_known = false});
        EXPECT_TRUE(read_image_header(path(name)).orientation_known) << name;
    }
    write_image(oblique, path("placed.nii.gz"), {.orientation_known = false});
    ImageHeader ph;
    const Grid<float> placed = read_image(path("placed.nii.gz"), kDefaultImageMemoryLimit, &ph);
    EXPECT_TRUE(ph.orientation_known);
    expect_same_geometry(placed.lattice(), oblique.lattice());
    for (const auto& name : listing()) EXPECT_EQ(name.find(".orient"), std::string::npos) << "left behind: " << name;
}

// FreeSurfer's MGH beyond the round trips (its geometry against nibabel: the Python suite): a header
// without goodRASflag reads as not oriented; more than one frame, a short file and another version
// are one line each.
TEST_F(ImageIo, FreeSurferMghHeadersAreReadAsTheySay) {
    const auto patched = [&](const std::string& name, std::size_t at, std::vector<unsigned char> bytes, std::size_t keep = 0) {
        write_image(test_image(), path(name));
        std::string all;
        {
            std::ifstream in(path(name), std::ios::binary);
            all.assign(std::istreambuf_iterator<char>(in), {});
        }
        std::copy(bytes.begin(), bytes.end(), all.begin() + static_cast<std::ptrdiff_t>(at));
        if (keep > 0) all.resize(keep);
        std::ofstream(path(name), std::ios::binary | std::ios::trunc) << all;
        return path(name);
    };
    write_image(test_image(), path("plain.mgh"));
    const ImageHeader plain = read_image_header(path("plain.mgh"));
    EXPECT_EQ(plain.format, "MGH");
    EXPECT_TRUE(plain.orientation_known);

    ImageHeader h;
    const Grid<float> unoriented = read_image(patched("flag0.mgh", 28, {0, 0}), kDefaultImageMemoryLimit, &h);  // goodRASflag 0
    EXPECT_FALSE(h.orientation_known);
    EXPECT_EQ(unoriented.lattice().spacing(), (Vec3d{1, 1, 1}));  // as nibabel: 1 mm, its default axes
    EXPECT_EQ(unoriented[PointIndex{17}], test_image()[PointIndex{17}]);

    expect_error([&] { read_image(patched("frames.mgh", 16, {0, 0, 0, 2})); }, path("frames.mgh"), "is a 4D image");
    expect_error([&] { read_image(patched("short.mgh", 0, {}, 284 + 40)); }, path("short.mgh"), "corrupt or truncated");
    expect_error([&] { read_image(patched("version.mgh", 0, {0, 0, 0, 2})); }, path("version.mgh"), "is not an MGH file (its version is 2, not 1)");
    expect_error([&] { read_image(patched("type.mgh", 20, {0, 0, 0, 6})); }, path("type.mgh"), "has MGH voxel type 6, which liveset does not read");
}

TEST_F(ImageIo, TwoFileFormatsGetFinalDataFileNames) {
    write_image(test_image(), path("vol.mhd"));
    write_image(test_image(), path("vol2.nhdr"));
    EXPECT_EQ(listing(), (std::set<std::string>{"vol.mhd", "vol.raw", "vol2.nhdr", "vol2.raw"}));
    std::ifstream in(path("vol.mhd"));
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(text.find("ElementDataFile = vol.raw"), std::string::npos) << text;
    // Still readable after moving the pair elsewhere (the reference is relative).
    fs::create_directory(dir_ / "moved");
    fs::rename(dir_ / "vol.mhd", dir_ / "moved" / "vol.mhd");
    fs::rename(dir_ / "vol.raw", dir_ / "moved" / "vol.raw");
    EXPECT_EQ(read_image((dir_ / "moved" / "vol.mhd").string()).dims(), (Vec3i{7, 9, 11}));
}

TEST_F(ImageIo, OverwriteReplacesTheFileAtomically) {
    const std::string file = path("out.nii.gz");
    write_image(test_image(), file);
    Grid<float> second = test_image();
    second.fill(42.0f);
    write_image(second, file);
    EXPECT_EQ(read_image(file)[5], 42.0f);
    EXPECT_EQ(listing(), std::set<std::string>{"out.nii.gz"});
}

TEST_F(ImageIo, AnyStoredPixelTypeReadsAsFloat) {
    const std::vector<std::pair<std::string, std::vector<unsigned char>>> cases = {
        {"MET_UCHAR", {0, 7, 200, 255, 1, 2, 3, 4}},
        {"MET_CHAR", {0, 7, 0x80, 0xFF, 1, 2, 3, 4}},  // 0x80 = -128, 0xFF = -1
    };
    for (const auto& [type, bytes] : cases) {
        const std::string file = path("t_" + type + ".mha");
        write_mha(file, "NDims = 3\nDimSize = 2 2 2\nElementType = " + type + "\n", bytes.data(), bytes.size());
        const Grid<float> g = read_image(file);
        EXPECT_EQ(g[2], type == "MET_UCHAR" ? 200.0f : -128.0f);
        EXPECT_EQ(g[3], type == "MET_UCHAR" ? 255.0f : -1.0f);
    }
    const short shorts[8] = {-1000, 0, 1, 2, 3, 4, 5, 32000};
    write_mha(path("s.mha"), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\n", shorts, sizeof shorts);
    EXPECT_EQ(read_image(path("s.mha"))[0], -1000.0f);
    EXPECT_EQ(read_image(path("s.mha"))[7], 32000.0f);
    const double doubles[8] = {0.25, -1.5, 1e6, 2, 3, 4, 5, 6};
    write_mha(path("d.mha"), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_DOUBLE\n", doubles, sizeof doubles);
    EXPECT_EQ(read_image(path("d.mha"))[1], -1.5f);
    EXPECT_EQ(read_image_header(path("d.mha")).pixel_type, "double");
}

TEST_F(ImageIo, FourDWithSingletonExtraAxisIsAccepted) {
    const float values[2 * 3 * 4] = {};
    write_mha(path("v.mha"), "NDims = 4\nDimSize = 2 3 4 1\nElementType = MET_FLOAT\n", values, sizeof values);
    EXPECT_EQ(read_image_header(path("v.mha")).dimension, 4);
    EXPECT_EQ(read_image(path("v.mha")).dims(), (Vec3i{2, 3, 4}));
}

// ---------------------------------------------------------------------------------------------
// DICOM series

TEST_F(ImageIo, DicomSeriesFolderReadsBack) {
    Grid<float> image(Lattice({6, 5, 8}, {0.8, 0.9, 2.5}, {-20, 15, 7.5}, rotation({1, 2, 3}, 25)));
    for (PointIndex i = 0; i < image.size(); ++i) image[i] = float(int(i * 7) % 500 - 100);
    const fs::path series = dir_ / "series";
    fs::create_directory(series);
    test::write_dicom_series(image, series.string(), 1);
    ASSERT_TRUE(is_dicom_series_dir(series.string()));
    EXPECT_FALSE(is_dicom_series_dir(dir_.string()));  // holds only a folder
    EXPECT_FALSE(is_dicom_series_dir(path("missing")));

    const ImageHeader h = read_image_header(series.string());
    EXPECT_EQ(h.format, "DICOM series");
    EXPECT_EQ(h.dims, (Vec3i{6, 5, 8}));
    const Grid<float> back = read_image(series.string());
    expect_same_geometry(image.lattice(), back.lattice(), 1e-3);
    for (PointIndex i = 0; i < image.size(); ++i) ASSERT_NEAR(back[i], image[i], 1e-3) << i;
}

TEST_F(ImageIo, DicomFolderWithSeveralSeriesReadsTheLargest) {
    const fs::path folder = dir_ / "dicom";
    fs::create_directory(folder);
    Grid<float> small(Lattice({4, 4, 3}, {1, 1, 1}));
    small.fill(5);
    Grid<float> large(Lattice({4, 4, 6}, {1, 1, 2}));
    large.fill(9);
    test::write_dicom_series(small, folder.string(), 1, "a");
    test::write_dicom_series(large, folder.string(), 2, "b");
    const ImageHeader h = read_image_header(folder.string());
    EXPECT_NE(h.format.find("largest of 2"), std::string::npos) << h.format;
    const Grid<float> g = read_image(folder.string());
    EXPECT_EQ(g.dims(), (Vec3i{4, 4, 6}));
    EXPECT_NEAR(g.lattice().spacing().z, 2.0, 1e-6);
    EXPECT_EQ(g[0], 9.0f);
}

TEST_F(ImageIo, DicomErrors) {
    const fs::path empty = dir_ / "empty";
    fs::create_directory(empty);
    write_text((empty / "notes.txt").string(), "not dicom");
    expect_error([&] { read_image(empty.string()); }, empty.string(), "no DICOM series");
    const fs::path one = dir_ / "one";
    fs::create_directory(one);
    Grid<float> slice(Lattice({5, 5, 1}));
    test::write_dicom_series(slice, one.string(), 3);
    expect_error([&] { read_image(one.string()); }, one.string(), "2D");
}

// ---------------------------------------------------------------------------------------------
// Refusals while reading

TEST_F(ImageIo, MissingFile) {
    expect_error([&] { read_image(path("nope.nii.gz")); }, path("nope.nii.gz"), "no such file or folder");
    expect_error([&] { read_image_header(path("nope.mha")); }, path("nope.mha"), "no such file or folder");
    expect_error([&] { read_label_image(path("nope")); }, path("nope"), "no such file or folder");
}

TEST_F(ImageIo, UnreadableFile) {
    if (::geteuid() == 0) GTEST_SKIP() << "running as root: file permissions are not enforced";
    write_image(test_image(), path("locked.nii"));
    fs::permissions(path("locked.nii"), fs::perms::none);
    expect_error([&] { read_image(path("locked.nii")); }, path("locked.nii"), "Permission denied");
}

TEST_F(ImageIo, UnknownFormat) {
    write_text(path("x.nii.gz"), "this is a text file, not an image\n");
    expect_error([&] { read_image(path("x.nii.gz")); }, path("x.nii.gz"), "unknown image format");
    write_text(path("y.png2"), "?");
    expect_error([&] { read_image(path("y.png2")); }, path("y.png2"), "unknown image format");
    write_text(path("z.mnc.gz"), std::string("\x1f\x8b\x08\x00", 4) + std::string(60, 'x'));  // BrainWeb serves its MINC gzipped
    expect_error([&] { read_image(path("z.mnc.gz")); }, path("z.mnc.gz"), "is a gzip-compressed MINC file");
    write_text(path("zero.nii"), "");
    expect_error([&] { read_image(path("zero.nii")); }, path("zero.nii"), "empty");
}

TEST_F(ImageIo, TruncatedFiles) {
    for (const std::string name : {"cut.nii", "cut.nii.gz", "cut.mha", "cut.nrrd"}) {
        const std::string file = path(name);
        write_image(test_image(), file);
        const auto size = fs::file_size(file);
        fs::resize_file(file, size / 2);
        expect_error([&] { read_image(file); }, file, "corrupt or truncated");
    }
    write_image(test_image(), path("lost.mhd"));
    fs::remove(path("lost.raw"));
    expect_error([&] { read_image(path("lost.mhd")); }, path("lost.mhd"), "corrupt or truncated");
}

// A two-file image (.hdr + .img: a NIfTI pair, as SPM writes it, or Analyze 7.5) is checked as a
// single file is: niftilib alone reads its NaN and infinite floats as 0 and zero-fills a short .img.
TEST_F(ImageIo, TwoFileNiftiAndAnalyzeAreCheckedAsASingleFileIs) {
    Grid<float> image = test_image();
    image[3] = std::numeric_limits<float>::quiet_NaN();
    image[10] = std::numeric_limits<float>::infinity();
    const auto analyze_copy = [&](const std::string& from, const std::string& to) {  // the pair's header without its "ni1" magic
        std::ifstream in(path(from + ".hdr"), std::ios::binary);
        std::string hdr((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ASSERT_EQ(hdr.substr(344, 3), "ni1");
        hdr.replace(344, 4, std::string(4, '\0'));
        write_text(path(to + ".hdr"), hdr);
        fs::copy_file(path(from + ".img"), path(to + ".img"), fs::copy_options::overwrite_existing);
    };
    write_image(image, path("pair.hdr"));
    ASSERT_TRUE(fs::exists(path("pair.img")));
    analyze_copy("pair", "analyze");
    for (const std::string name : {"pair.hdr", "pair.img", "analyze.hdr", "analyze.img"}) {
        expect_error([&] { read_image(path(name)); }, path(name), "2 voxels are NaN or infinite");
        expect_error([&] { read_image(path(name), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep); }, path(name), "1 voxel is infinite");
    }
    image[10] = 2.5f;
    write_image(image, path("pair.hdr"));
    analyze_copy("pair", "analyze");
    for (const std::string name : {"pair.hdr", "analyze.img"}) {
        const Grid<float> back = read_image(path(name), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep);
        for (PointIndex i = 0; i < image.size(); ++i) {
            if (std::isnan(image[i])) EXPECT_TRUE(std::isnan(back[i])) << name << " " << i;
            else EXPECT_EQ(back[i], image[i]) << name << " " << i;
        }
    }
    write_image(test_image(), path("cut.hdr"));
    fs::resize_file(path("cut.img"), fs::file_size(path("cut.img")) / 2);
    expect_error([&] { read_image(path("cut.hdr")); }, path("cut.hdr"), "corrupt or truncated");
    expect_error([&] { read_label_image(path("cut.img")); }, path("cut.img"), "corrupt or truncated");
}

TEST_F(ImageIo, TwoDImage) {
    const float v[12] = {};
    write_mha(path("flat.mha"), "NDims = 2\nDimSize = 3 4\nElementType = MET_FLOAT\n", v, sizeof v);
    expect_error([&] { read_image(path("flat.mha")); }, path("flat.mha"), "2D");
    EXPECT_EQ(read_image_header(path("flat.mha")).dimension, 2);  // the header still reads
    write_mha(path("slice.mha"), "NDims = 3\nDimSize = 3 4 1\nElementType = MET_FLOAT\n", v, sizeof v);
    expect_error([&] { read_image(path("slice.mha")); }, path("slice.mha"), "2D");
}

TEST_F(ImageIo, FourDImage) {
    const float v[2 * 2 * 2 * 3] = {};
    write_mha(path("time.mha"), "NDims = 4\nDimSize = 2 2 2 3\nElementType = MET_FLOAT\n", v, sizeof v);
    expect_error([&] { read_image(path("time.mha")); }, path("time.mha"), "4D");
}

TEST_F(ImageIo, RgbImage) {
    const unsigned char v[2 * 2 * 2 * 3] = {};
    write_mha(path("rgb.mha"), "NDims = 3\nDimSize = 2 2 2\nElementNumberOfChannels = 3\nElementType = MET_UCHAR\n", v,
              sizeof v);
    EXPECT_EQ(read_image_header(path("rgb.mha")).components, 3);
    expect_error([&] { read_image(path("rgb.mha")); }, path("rgb.mha"), "3 components per voxel");
    expect_error([&] { read_label_image(path("rgb.mha")); }, path("rgb.mha"), "3 components per voxel");
}

TEST_F(ImageIo, EmptyImage) {
    write_text(path("e.mha"),
               "ObjectType = Image\nNDims = 3\nDimSize = 4 0 4\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n");
    expect_error([&] { read_image(path("e.mha")); }, path("e.mha"), "image is empty (size 4x0x4)");
    // teem refuses a zero size while parsing the header already.
    write_text(path("e.nhdr"), "NRRD0004\ntype: float\ndimension: 3\nsizes: 0 4 4\nencoding: raw\ndata file: e.raw\n");
    write_text(path("e.raw"), "");
    expect_error([&] { read_image(path("e.nhdr")); }, path("e.nhdr"), "size is zero");
}

TEST_F(ImageIo, NanVoxels) {
    Grid<float> image = test_image();
    image[3] = std::numeric_limits<float>::quiet_NaN();
    image[10] = std::numeric_limits<float>::infinity();
    image[11] = -std::numeric_limits<float>::infinity();
    write_image(image, path("nan.nii.gz"));  // writing is faithful
    expect_error([&] { read_image(path("nan.nii.gz")); }, path("nan.nii.gz"), "3 voxels are NaN or infinite");
    expect_error([&] { read_label_image(path("nan.nii.gz")); }, path("nan.nii.gz"), "NaN or infinite");
    // A scan's NaN are its "no data" (NanVoxels::keep): read where the file holds them (niftilib
    // alone reads a NIfTI's as 0), whatever the format; infinite voxels are still damage.
    expect_error([&] { read_image(path("nan.nii.gz"), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep); }, path("nan.nii.gz"),
                 "2 voxels are infinite");
    image[10] = image[11] = 1.5f;
    image[40] = std::numeric_limits<float>::quiet_NaN();
    for (const std::string name : {"nan_only.nii.gz", "nan_only.nii", "nan_only.mha", "nan_only.nrrd", "nan_only.mgz", "nan_only.mnc"}) {
        write_image(image, path(name));
        expect_error([&] { read_image(path(name)); }, path(name), "2 voxels are NaN or infinite");
        const Grid<float> back = read_image(path(name), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep);
        ASSERT_EQ(back.size(), image.size()) << name;
        for (PointIndex i = 0; i < image.size(); ++i) {
            if (std::isnan(image[i])) EXPECT_TRUE(std::isnan(back[i])) << name << " " << i;
            else EXPECT_EQ(back[i], image[i]) << name << " " << i;
        }
    }
}

TEST_F(ImageIo, AbsurdSizeFailsFastWithoutAllocating) {
    const auto start = std::chrono::steady_clock::now();
    write_text(path("huge.mhd"), "ObjectType = Image\nNDims = 3\nDimSize = 1000000 1000000 1000000\n"
                                 "ElementType = MET_FLOAT\nElementDataFile = huge.raw\n");
    write_text(path("huge.raw"), "tiny");
    expect_error([&] { read_image(path("huge.mhd")); }, path("huge.mhd"), "too large");
    expect_error([&] { read_label_image(path("huge.mhd")); }, path("huge.mhd"), "too large");
    write_text(path("huge.nhdr"), "NRRD0004\ntype: short\ndimension: 3\nsizes: 1000000 1000000 1000000\n"
                                  "encoding: raw\nendian: little\ndata file: huge.raw\n");
    expect_error([&] { read_image(path("huge.nhdr")); }, path("huge.nhdr"), "too large");
    EXPECT_EQ(read_image_header(path("huge.nhdr")).dims, (Vec3i{1000000, 1000000, 1000000}));
    // Under the point limit but over a given memory limit.
    write_image(test_image(), path("small.nii"));
    expect_error([&] { read_image(path("small.nii"), 1000); }, path("small.nii"), "memory limit");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 2.0);
}

TEST_F(ImageIo, BadSpacingAndDirection) {
    const float v[8] = {};
    write_mha(path("neg.mha"), "NDims = 3\nDimSize = 2 2 2\nElementSpacing = -1 1 1\nElementType = MET_FLOAT\n", v,
              sizeof v);
    expect_error([&] { read_image(path("neg.mha")); }, path("neg.mha"), "invalid spacing");
    write_mha(path("zero.mha"), "NDims = 3\nDimSize = 2 2 2\nElementSpacing = 1 0 1\nElementType = MET_FLOAT\n", v,
              sizeof v);
    expect_error([&] { read_image(path("zero.mha")); }, path("zero.mha"), "invalid spacing");
    write_text(path("neg.nhdr"), "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nspacings: 1 -2 1\n"
                                 "encoding: raw\nendian: little\ndata file: neg.raw\n");
    std::ofstream(path("neg.raw"), std::ios::binary).write(reinterpret_cast<const char*>(v), sizeof v);
    expect_error([&] { read_image(path("neg.nhdr")); }, path("neg.nhdr"), "invalid spacing");
    write_mha(path("sing.mha"),
              "NDims = 3\nDimSize = 2 2 2\nTransformMatrix = 1 0 0 1 0 0 0 0 1\nElementType = MET_FLOAT\n", v,
              sizeof v);
    expect_error([&] { read_image(path("sing.mha")); }, path("sing.mha"), "singular");
}

TEST_F(ImageIo, LabelValuesMustBeIntegersIn0To255) {
    Grid<float> image = test_image();  // non-integer values
    write_image(image, path("f.nii.gz"));
    expect_error([&] { read_label_image(path("f.nii.gz")); }, path("f.nii.gz"), "not an integer in 0..255");
    const short big[8] = {0, 1, 2, 300, 4, 5, 6, 7};
    write_mha(path("big.mha"), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\n", big, sizeof big);
    const std::string msg =
        expect_error([&] { read_label_image(path("big.mha")); }, path("big.mha"),
                     "1 voxel is not an integer in 0..255");
    EXPECT_NE(msg.find("300"), std::string::npos) << msg;
    const short neg[8] = {0, -1, 2, 3, 4, 5, 6, 7};
    write_mha(path("neg.mha"), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\n", neg, sizeof neg);
    expect_error([&] { read_label_image(path("neg.mha")); }, path("neg.mha"), "not an integer in 0..255");
    // Integer-valued floats and wide integer types are fine.
    const float fl[8] = {0, 1, 2, 255, 4, 5, 6, 7};
    write_mha(path("ok.mha"), "NDims = 3\nDimSize = 2 2 2\nElementType = MET_FLOAT\n", fl, sizeof fl);
    EXPECT_EQ(read_label_image(path("ok.mha"))[3], 255);
}

// ---------------------------------------------------------------------------------------------
// Refusals while writing; nothing half-written is ever left behind

TEST_F(ImageIo, WriteIntoMissingFolder) {
    const std::string file = path("no/such/folder/out.nii.gz");
    expect_error([&] { write_image(test_image(), file); }, file, "does not exist");
    EXPECT_EQ(listing(), std::set<std::string>{});
}

TEST_F(ImageIo, WriteIntoUnwritableFolder) {
    if (::geteuid() == 0) {
        // Root ignores permission bits; /proc refuses new files even to root.
        const std::string file = "/proc/liveset_io_test.nii.gz";
        expect_error([&] { write_image(test_image(), file); }, file, "cannot write");
        for (const auto& e : fs::directory_iterator("/proc"))
            EXPECT_EQ(e.path().filename().string().find("liveset_io_test"), std::string::npos);
        return;
    }
    const fs::path ro = dir_ / "readonly";
    fs::create_directory(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    const std::string file = (ro / "out.nii.gz").string();
    expect_error([&] { write_image(test_image(), file); }, file, "ermission denied");
    EXPECT_TRUE(listing(ro).empty());
    fs::permissions(ro, fs::perms::owner_all);
}

TEST_F(ImageIo, WriteBadTargets) {
    expect_error([&] { write_image(test_image(), path("out.xyz")); }, path("out.xyz"), "unknown image format");
    expect_error([&] { write_image(test_image(), path("noext")); }, path("noext"), "extension");
    expect_error([&] { write_image(test_image(), path("out.dcm")); }, path("out.dcm"), "DICOM");
    fs::create_directory(dir_ / "sub.nii");
    expect_error([&] { write_image(test_image(), path("sub.nii")); }, path("sub.nii"), "is a folder");
    expect_error([&] { write_image(Grid<float>(), path("e.nii")); }, path("e.nii"), "empty");
    EXPECT_EQ(listing(), std::set<std::string>{"sub.nii"});
}

// Disk full: a tiny tmpfs (needs root and mount permission; skipped otherwise).
TEST_F(ImageIo, WriteOnFullDiskLeavesNothing) {
    const fs::path mnt = dir_ / "tiny";
    fs::create_directory(mnt);
    if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=16k") != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs (" << std::strerror(errno) << ")";
    struct Unmount {
        fs::path at;
        // Lazy: a writer that failed may still hold a descriptor on the full file system.
        ~Unmount() { ::umount2(at.c_str(), MNT_DETACH); }
    } unmount{mnt};
    Grid<float> big(Lattice({40, 40, 40}));  // 256 kB as float
    std::uint32_t state = 12345;  // incompressible values, so compressed formats overflow too
    for (PointIndex i = 0; i < big.size(); ++i) {
        state = state * 1664525u + 1013904223u;
        big[i] = float(state >> 8) * 1e-3f;
    }
    // Compressed output: its size is unknown until written, so the write itself fails.
    for (const std::string name : {"full.nii.gz", "full.mha", "full.nrrd"}) {
        const std::string file = (mnt / name).string();
        expect_error([&] { write_image(big, file); }, file, "cannot write");
        EXPECT_TRUE(listing(mnt).empty()) << name << " left " << *listing(mnt).begin();
        EXPECT_EQ(fs::space(mnt).available, fs::space(mnt).capacity) << name << " still holds disk space";
    }
    // Uncompressed output (and MINC) is refused before writing.
    for (const std::string name : {"full.nii", "full.mhd", "full.nhdr", "full.mnc"}) {
        const std::string file = (mnt / name).string();
        expect_error([&] { write_image(big, file); }, file, "not enough free space");
        EXPECT_TRUE(listing(mnt).empty()) << name;
    }
}

// ---------------------------------------------------------------------------------------------
// Real data: BrainWeb (bundled in data/brainweb)

TEST(ImageIoData, BrainWeb) {
    const std::string base = std::string(LIVESET_DATA_DIR) + "/brainweb/";
    ASSERT_TRUE(fs::exists(base + "t1.mha")) << "no BrainWeb data in " << base;
    const Grid<float> t1 = read_image(base + "t1.mha");
    const Grid<std::uint8_t> labels = read_label_image(base + "labels_crisp.nii.gz");
    const Grid<std::uint8_t> mask = read_label_image(base + "brain_mask.nii.gz");
    for (const std::string name : {"t1.mha", "labels_crisp.nii.gz", "brain_mask.nii.gz"}) {
        const ImageHeader h = read_image_header(base + name);
        std::cout << name << ": " << h.format << ' ' << h.pixel_type << ", " << h.dims.x << 'x' << h.dims.y << 'x'
                  << h.dims.z << ", spacing " << h.spacing << ", origin " << h.origin << ", direction";
        for (double v : h.direction) std::cout << ' ' << v;
        std::cout << '\n';
    }
    EXPECT_EQ(t1.dims(), labels.dims());
    EXPECT_EQ(t1.dims(), mask.dims());
    EXPECT_TRUE(labels.lattice().same_geometry(t1.lattice(), 1e-3));
    EXPECT_TRUE(mask.lattice().same_geometry(t1.lattice(), 1e-3));
    std::uint8_t max_label = 0;
    std::size_t brain = 0;
    for (auto v : labels.values()) max_label = std::max(max_label, v);
    for (auto v : mask.values()) brain += v != 0;
    std::cout << "labels 0.." << int(max_label) << ", brain mask " << brain << " of " << mask.size() << " voxels\n";
    EXPECT_GT(max_label, 1);
    EXPECT_GT(brain, mask.size() / 20);
    EXPECT_LT(brain, mask.size() / 2);
}

}  // namespace
}  // namespace liveset
