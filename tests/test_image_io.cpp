// Image output: formats by extension, round trips, metadata, and the checks made before
// rendering (unknown extension, unwritable path, no overwrite without --force).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <filesystem>

#include "base/error.h"
#include "image/error_metrics.h"
#include "image/image_io.h"
#include "test_support.h"

namespace fh {
namespace {

Image gradient(int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.rgb.insert(img.rgb.end(), {x / float(w), y / float(h), 2.5f});
  return img;
}

TEST(ImageIo, ExrKeepsLinearFloatsAndMetadata) {
  const std::string path = test::tempDir("img") + "/a.exr";
  const Image img = gradient(7, 5);
  writeImage(path, img, {{"spp", "16"}, {"method", "mis"}});
  const Image back = readImage(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (size_t i = 0; i < img.rgb.size(); ++i) EXPECT_FLOAT_EQ(back.rgb[i], img.rgb[i]);
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("fredholm:spp"), "16");
  EXPECT_EQ(in->spec().get_string_attribute("fredholm:method"), "mis");
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
}

TEST(ImageIo, PngIsSrgbEncodedAndTopRowFirst) {
  const std::string path = test::tempDir("img") + "/a.png";
  Image img = gradient(4, 4);
  img.rgb[0] = 0.2f;  // top-left red
  writeImage(path, img, {});
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  std::vector<unsigned char> px(4 * 4 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  EXPECT_EQ(px[0], (unsigned char)std::lround(255.f * linearToSrgb(0.2f)));  // 124, not 51
  EXPECT_EQ(px[2], 255);                                                      // 2.5 clamps
  EXPECT_EQ(px[3 * 4 * 3 + 1], (unsigned char)std::lround(255.f * linearToSrgb(0.75f)));
}

TEST(ImageIo, HdrAndPfmAreFloat) {
  const std::string dir = test::tempDir("img");
  for (const char* ext : {".hdr", ".pfm"}) {
    writeImage(dir + "/a" + ext, gradient(3, 2), {});
    const Image back = readImage(dir + "/a" + ext);
    EXPECT_NEAR(back.rgb[5], 2.5f, 0.05f) << ext;  // above 1: not clamped
  }
}

TEST(ImageIo, ChecksBeforeRendering) {
  const std::string dir = test::tempDir("img");
  EXPECT_EQ(checkOutputPath(dir + "/x.EXR", false), ImageEncoding::LinearFloat);
  EXPECT_EQ(checkOutputPath(dir + "/x.jpg", false), ImageEncoding::Srgb8);
  try {
    checkOutputPath(dir + "/x.tga", false);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("-o '" + dir + "/x.tga': unknown image extension '.tga'"),
              std::string::npos);
  }
  EXPECT_THROW(checkOutputPath(dir + "/no/such/dir/x.png", false), Error);
  test::writeFile(dir + "/old.png", "x");
  EXPECT_THROW(checkOutputPath(dir + "/old.png", false), Error);
  EXPECT_NO_THROW(checkOutputPath(dir + "/old.png", true));
  EXPECT_EQ(firstFreeName(dir + "/old.png"), dir + "/old-1.png");
  EXPECT_EQ(firstFreeName(dir + "/new.png"), dir + "/new.png");
}

TEST(ImageIoCli, ExistingOutputIsNotOverwrittenWithoutForce) {
  const std::string dir = test::tempDir("img");
  test::writeFile(dir + "/keep.png", "precious");
  const auto r = test::runFredholm("render -o " + dir + "/keep.png --width 8 --height 8");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("file exists (pass --force"), std::string::npos) << r.output;
  std::ifstream in(dir + "/keep.png");
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
  const auto forced = test::runFredholm("render -o " + dir + "/keep.png --width 8 --height 8 --force");
  EXPECT_EQ(forced.exitCode, 0) << forced.output;
  EXPECT_EQ(readImage(dir + "/keep.png").width, 8);
}

TEST(ImageIoCli, DefaultNameStepsAside) {
  const std::string dir = test::tempDir("img");
  const auto first = test::runFredholm("render --width 8 --height 8", "cd " + dir + " &&");
  ASSERT_EQ(first.exitCode, 0) << first.output;
  const auto second = test::runFredholm("render --width 8 --height 8", "cd " + dir + " &&");
  ASSERT_EQ(second.exitCode, 0) << second.output;
  EXPECT_NE(second.output.find("wrote fredholm-1.png"), std::string::npos) << second.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/fredholm.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/fredholm-1.png"));
}

}  // namespace
}  // namespace fh

namespace fh {
namespace {

TEST(ErrorMetrics, KnownValues) {
  Image ref, img;
  ref.width = img.width = 2;
  ref.height = img.height = 1;
  ref.rgb = {1.f, 1.f, 1.f, 0.f, 0.f, 0.f};
  img.rgb = {1.5f, 1.f, 1.f, 0.1f, 0.f, 0.f};
  const ImageError e = imageError(img, ref);
  // relMSE: (0.25 / 1.01 + 0.01 / 0.01) / 6; RMSE: sqrt(0.26 / 6); MAE: 0.6 / 6.
  EXPECT_NEAR(e.relMse, (0.25 / 1.01 + 1.0) / 6.0, 1e-6);
  EXPECT_NEAR(e.rmse, std::sqrt(0.26 / 6.0), 1e-6);
  EXPECT_NEAR(e.mae, 0.1, 1e-6);
  EXPECT_EQ(imageError(ref, ref).relMse, 0.0);
  Image small = ref;
  small.width = 1;
  EXPECT_THROW(imageError(small, ref), Error);
  EXPECT_NEAR(e.meanImage[0], 0.8, 1e-6);
  EXPECT_NEAR(e.meanReference[0], 0.5, 1e-6);
}

TEST(ErrorMetrics, BlockAverage) {
  Image img;
  img.width = 4;
  img.height = 2;
  for (int i = 0; i < 8; ++i) img.rgb.insert(img.rgb.end(), {float(i), 1.f, 0.f});
  const Image b = blockAverage(img, 2);
  ASSERT_EQ(b.width, 2);
  ASSERT_EQ(b.height, 1);
  EXPECT_EQ(b.rgb, (std::vector<float>{(0 + 1 + 4 + 5) / 4.f, 1.f, 0.f, (2 + 3 + 6 + 7) / 4.f, 1.f, 0.f}));
  EXPECT_EQ(blockAverage(img, 1).rgb, img.rgb);
  EXPECT_THROW(blockAverage(img, 3), Error);
  EXPECT_THROW(blockAverage(img, 0), Error);
}

}  // namespace
}  // namespace fh
