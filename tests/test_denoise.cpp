// --denoise (image/denoiser.h): Open Image Denoise's output beside the unbiased image, never
// instead of it; its error against a long render; and the library's absence as a one-line
// error before any work. setup.sh installs OIDN, so these run wherever the suite runs.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "image/error_metrics.h"
#include "image/image_io.h"
#include "test_support.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

std::string metadataOf(const std::string& path, const std::string& key) {
  auto in = OIIO::ImageInput::open(path);
  return in ? in->spec().get_string_attribute("fredholm:" + key) : "(unreadable)";
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

size_t filesIn(const std::string& dir) {
  return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

double mean(const Image& image) {
  double sum = 0;
  for (float v : image.rgb) sum += v;
  return sum / double(image.rgb.size());
}

const std::string kCornell = " --width 128 --height 128 --method mis";

// The target: at 16 spp the denoised image's relMSE is at most a quarter of the noisy
// one's, against a 1024-spp render of another seed (whose own relMSE is about 1/64 of the noisy
// image's, so it cannot carry the comparison). The denoiser's bias shows in the mean: it may
// blur, not darken or brighten the image.
TEST(Denoise, QuartersTheErrorAt16SppOnTheCornellBox) {
  const std::string dir = test::tempDir("denoise");
  const auto noisy = test::runFredholm("render" + kCornell + " --spp 16 --seed 7 --denoise -o " + dir + "/n.exr");
  ASSERT_EQ(noisy.exitCode, 0) << noisy.output;
  const auto reference = test::runFredholm("render" + kCornell + " --spp 1024 --seed 99 -o " + dir + "/ref.exr");
  ASSERT_EQ(reference.exitCode, 0) << reference.output;
  const Image ref = readImage(dir + "/ref.exr");
  const double noisyError = imageError(readImage(dir + "/n.exr"), ref).relMse;
  const Image denoised = readImage(dir + "/n.denoised.exr");
  const double denoisedError = imageError(denoised, ref).relMse;
  EXPECT_LE(denoisedError, 0.25 * noisyError) << "noisy " << noisyError << ", denoised " << denoisedError;
  EXPECT_NEAR(mean(denoised) / mean(ref), 1.0, 0.03);
}

// The image -o names holds the same pixels with --denoise as without; the denoised one says
// so in its metadata, with the render's own.
TEST(Denoise, WritesBesideTheImageNeverInsteadOfIt) {
  const std::string dir = test::tempDir("denoise");
  const std::string flags = " --width 32 --height 24 --spp 4 --seed 3";
  ASSERT_EQ(test::runFredholm("render" + flags + " --denoise -o " + dir + "/a.exr").exitCode, 0);
  ASSERT_EQ(test::runFredholm("render" + flags + " -o " + dir + "/b.exr").exitCode, 0);
  EXPECT_EQ(readImage(dir + "/a.exr").rgb, readImage(dir + "/b.exr").rgb);
  EXPECT_NE(metadataOf(dir + "/a.denoised.exr", "denoised").find("Open Image Denoise"), std::string::npos);
  EXPECT_EQ(metadataOf(dir + "/a.exr", "denoised"), "");
  EXPECT_EQ(metadataOf(dir + "/a.denoised.exr", "spp"), metadataOf(dir + "/a.exr", "spp"));
  EXPECT_NE(readImage(dir + "/a.denoised.exr").rgb, readImage(dir + "/a.exr").rgb);

  // A PNG's twin is a PNG; the default name's twin follows it.
  const auto png = test::runCommand("cd " + dir + " && " + FREDHOLM_BINARY + " render" + flags + " --denoise");
  ASSERT_EQ(png.exitCode, 0) << png.output;
  EXPECT_TRUE(fs::exists(dir + "/fredholm.png") && fs::exists(dir + "/fredholm.denoised.png")) << png.output;
}

// Without the library, --denoise fails at once in one line that says how to get it, and
// writes nothing.
TEST(Denoise, WithoutTheLibraryIsAOneLineErrorBeforeWork) {
  const std::string dir = test::tempDir("denoise");
  const auto r = test::runFredholm("render --width 8 --height 8 --spp 1 --denoise -o " + dir + "/x.exr",
                                   "FREDHOLM_OIDN=" + dir + "/libOpenImageDenoise.so.2");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("fredholm: error: FREDHOLM_OIDN", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("./setup.sh build installs it"), std::string::npos) << r.output;
  EXPECT_EQ(filesIn(dir), 0u);
}

// The denoised image is an output of the plan like any other: refused where it would replace
// a file, and asked for only where there is an image to denoise.
TEST(Denoise, TheDenoisedImageIsPlannedLikeEveryOutput) {
  const std::string dir = test::tempDir("denoise");
  test::writeFile(dir + "/x.denoised.exr", "mine");
  const std::string small = "render --width 8 --height 8 --spp 1 --denoise";
  const std::pair<std::string, std::string> cases[] = {
      {" -o " + dir + "/x.exr", "--denoise '" + dir + "/x.denoised.exr': file exists"},
      {" --film " + dir + "/f.film", "--denoise writes NAME.denoised.EXT beside the image: give -o"},
      {" --aov albedo -o " + dir + "/y.exr", "--denoise works on a render's radiance"},
      {" -o " + dir + "/z.exr --stats " + dir + "/z.denoised.exr", "is also the file of"}};
  for (const auto& [flags, message] : cases) {
    const auto r = test::runFredholm(small + flags);
    EXPECT_NE(r.exitCode, 0) << flags;
    EXPECT_NE(r.output.find(message), std::string::npos) << flags << "\n" << r.output;
  }
  EXPECT_EQ(readAll(dir + "/x.denoised.exr"), "mine");
  ASSERT_EQ(test::runFredholm(small + " -o " + dir + "/x.exr --force").exitCode, 0);
  EXPECT_NE(metadataOf(dir + "/x.denoised.exr", "denoised"), "");
}

}  // namespace
}  // namespace fh
