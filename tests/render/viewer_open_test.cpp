// Opening an image from the viewer's panel: the read and N4 run on a worker thread while frames go
// on, and a frame swaps the new session in - the image the command line's `view` would give
// (prepare_image: N4 by default); a second open waits its turn; Cancel keeps the current session;
// a file that cannot be read fails in one line and keeps it too. A full head opens in its automatic
// brain mask, as `view IMAGE` opens it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "analytic_head.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/render/headless_context.hpp"
#include "scratch_dir.hpp"
#include "viewer.hpp"
#include "workspace.hpp"

namespace liveset::viewer {
namespace {

namespace fs = std::filesystem;

const std::string& image_path() {
    static const std::string path = [] {
        PhantomOptions o;
        o.size = 48;
        const fs::path p = testing::scratch_dir("viewer_open_test") / "t1.nii.gz";
        write_image(make_phantom(o).image, p.string());
        return p.string();
    }();
    return path;
}

ViewerConfig headless() {
    ViewerConfig c;
    c.headless = true;
    return c;
}

// Frames until the open finished (at most `limit`); false if it did not.
bool frames_until_opened(Viewer& v, const render::Framebuffer& fb, int limit = 100000) {
    for (int n = 0; n < limit && v.opening(); ++n) v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    return !v.opening();
}

}  // namespace

TEST(ViewerOpen, AnImageOpensOnAWorkerAndAFrameSwapsItIn) {
    render::HeadlessContext context;
    render::Framebuffer fb(640, 480);
    Viewer v(nullptr, "", headless());
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    ASSERT_TRUE(v.open_image(image_path())) << v.message();
    EXPECT_EQ(v.session(), nullptr);  // nothing is swapped in outside a frame
    EXPECT_TRUE(v.needs_frame());     // the window keeps drawing (and polling) meanwhile
    ASSERT_TRUE(v.opening());  // until a frame takes the result, however fast the worker was
    EXPECT_FALSE(v.open_image(image_path()));
    EXPECT_NE(v.message().find("still opening"), std::string::npos) << v.message();
    ASSERT_TRUE(frames_until_opened(v, fb));
    ASSERT_NE(v.session(), nullptr) << v.message();
    EXPECT_EQ(v.message(), "opened " + image_path());
    Grid<float> expected = read_image(image_path());
    std::optional<cli::Roi> no_roi;
    const cli::PreparedImage prepared = cli::prepare_image(expected, no_roi, cli::BiasCorrection::kDefault);
    ASSERT_TRUE(prepared.bias.has_value());
    EXPECT_EQ(image_checksum(v.session()->image()), image_checksum(expected));  // corrected as `view` corrects it
    EXPECT_NE(image_checksum(v.session()->image()), image_checksum(read_image(image_path())));
}

TEST(ViewerOpen, AHeadOpensInItsAutomaticBrainMaskAsViewDoes) {
    render::HeadlessContext context;
    render::Framebuffer fb(640, 480);
    const std::string head = (testing::scratch_dir("viewer_open_head") / "head.nii.gz").string();  // not image_path()'s folder, which scratch_dir empties
    write_image(testing::analytic_head(false), head);
    Viewer v(nullptr, "", headless());
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    ASSERT_TRUE(v.open_image(head));
    ASSERT_TRUE(frames_until_opened(v, fb));
    ASSERT_NE(v.session(), nullptr) << v.message();
    EXPECT_EQ(v.message(), "opened " + head + ", the front bounded by the automatic brain mask");
    Grid<float> image = read_image(head);
    std::optional<cli::Roi> roi = cli::load_roi("", image);  // `view IMAGE`'s default
    cli::prepare_image(image, roi, cli::BiasCorrection::kDefault);
    ASSERT_TRUE(roi.has_value() && roi->by_default);
    ASSERT_NE(v.session()->roi(), nullptr);
    EXPECT_EQ(mask_checksum(*v.session()->roi()), mask_checksum(roi->mask));
    EXPECT_EQ(image_checksum(v.session()->image()), image_checksum(image));
    EXPECT_FALSE(v.add_seed({2, 2, 2}, 2.0));  // the air: refused, and told how to segment outside the brain
    EXPECT_NE(v.message().find("lies outside the region of interest"), std::string::npos) << v.message();
    EXPECT_NE(v.message().find("open the image with --roi none"), std::string::npos) << v.message();
    EXPECT_TRUE(v.add_seed({32, 32, 32}, 2.0)) << v.message();
}

TEST(ViewerOpen, CancelAndAnUnreadableFileKeepTheCurrentSession) {
    render::HeadlessContext context;
    render::Framebuffer fb(640, 480);
    Viewer v(nullptr, "", headless());
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    ASSERT_TRUE(v.open_image(image_path()));
    ASSERT_TRUE(frames_until_opened(v, fb));
    const Session* first = v.session();
    ASSERT_NE(first, nullptr) << v.message();

    ASSERT_TRUE(v.open_image(image_path()));
    v.cancel_open();  // whether the worker finished or not, its image is dropped
    ASSERT_TRUE(frames_until_opened(v, fb));
    EXPECT_EQ(v.session(), first);
    EXPECT_EQ(v.message(), "opening " + image_path() + " cancelled");

    const std::string missing = (fs::path(image_path()).parent_path() / "missing.nii.gz").string();
    ASSERT_TRUE(v.open_image(missing));
    ASSERT_TRUE(frames_until_opened(v, fb));
    EXPECT_EQ(v.session(), first);
    EXPECT_NE(v.message().find("missing.nii.gz"), std::string::npos) << v.message();
    EXPECT_EQ(v.message().find('\n'), std::string::npos) << v.message();
}

}  // namespace liveset::viewer
