// --noise: a render stops once the film's estimated relMSE meets the target. The estimate
// (Film::estimatedRelMse, from two independently scrambled replicates) is checked against
// the truth, the relMSE against a long reference, on the Cornell box and the Veach plates:
// within a factor 1.5 where the render stops. The reference's own error (its estimate)
// is taken off the measured relMSE.
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "image/error_metrics.h"
#include "render/render.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

// Renders to each target, then checks the film's estimate against the error measured.
void expectEstimateNearTheTruth(const Scene& scene, int width, int height, int referenceSpp,
                                std::initializer_list<double> targets) {
  RenderSettings s = test::renderSettings();
  s.width = width;
  s.height = height;
  s.spp = referenceSpp;
  // The reference with two replicates too (a target it never reaches), for its own error.
  s.noise = 1e-12;
  s.seed = 1000;
  const Film reference = test::render(scene, scene.camera, s).film;
  for (double target : targets) {
    for (unsigned seed : {1u, 2u}) {
      s.noise = target;
      s.seed = seed;
      const Film film = test::render(scene, scene.camera, s).film;
      const double estimate = film.estimatedRelMse();
      EXPECT_LE(estimate, target);
      EXPECT_GE(film.passes(), uint64_t(kNoiseMinPasses));
      EXPECT_LT(film.passes(), uint64_t(referenceSpp) / 8) << "the reference is too short for this target";
      const double truth = imageError(film.image(), reference.image()).relMse - reference.estimatedRelMse();
      const std::string where = "target " + std::to_string(target) + ", seed " + std::to_string(seed) + ", " +
                                std::to_string(film.passes()) + " passes";
      EXPECT_GT(truth, estimate / 1.5) << where;
      EXPECT_LT(truth, estimate * 1.5) << where;
    }
  }
}

TEST(NoiseTarget, EstimateMatchesTheTruthOnTheCornellBox) {
  expectEstimateNearTheTruth(loadDefaultScene(), 32, 32, 4096, {3e-3});
}

// Near-mirror plates and small bright lights: heavy-tailed samples, the hard case for an
// error estimate from the samples themselves (at 3e-2 few of the rare bright samples have
// shown up yet). Large enough that the lights' reflections span a few pixels: where a
// pixel's neighbours are all unlike it, their mean is a poor stand-in for its value.
TEST(NoiseTarget, EstimateMatchesTheTruthOnTheVeachPlates) {
  expectEstimateNearTheTruth(loadScene(test::testScene("veach/veach-plates.obj")), 96, 64, 16384, {3e-2, 1e-2});
}

// The typical estimate (the median of five interleaved sets' means) is the mean estimate
// where the noise is even and where it is all in one region, which each set samples alike;
// one pixel's firefly, which decides the mean, moves it by little.
TEST(NoiseEstimate, TheTypicalEstimateIsTheMeanButForAFewPixels) {
  const auto none = [](int, int) { return false; };
  // Each set's mean has a relative deviation of about 2 % (4 % in the region's case).
  const Film even = test::noisyFilm(100, 16, 0.1, 0.1, none, 1);
  EXPECT_NEAR(even.typicalRelMse(), even.estimatedRelMse(), 0.1 * even.estimatedRelMse());
  // A quarter of the image ten times as noisy: a hundred times the error there.
  const Film region = test::noisyFilm(100, 16, 0.1, 1.0, [](int x, int y) { return x < 50 && y < 50; }, 2);
  EXPECT_GT(region.estimatedRelMse(), 20 * even.estimatedRelMse());
  EXPECT_NEAR(region.typicalRelMse(), region.estimatedRelMse(), 0.15 * region.estimatedRelMse());
  // A firefly in each of two pixels, (1, 1) and (50, 50), of sets 3 and 0: a sample of 1000.
  Film fireflies = even;
  fireflies.addPass(test::passWithFireflies(fireflies, {101, 5050}, 1000.f));
  EXPECT_GT(fireflies.estimatedRelMse(), 100 * even.estimatedRelMse());
  EXPECT_LT(fireflies.typicalRelMse(), 1.5 * even.typicalRelMse());
}

// Stopping is decided on merged passes only, so the image for a seed and target is the
// same whatever the wavefront size (which changes how many passes are in flight).
TEST(NoiseTarget, TheStopIsDeterministic) {
  DeviceContext& dc = test::defaultDevice();
  const Scene scene = loadDefaultScene();
  const Bvh bvh = buildBvh(scene);
  RenderSettings s = test::renderSettings();
  s.width = s.height = 24;
  s.spp = 4096;
  s.noise = 3e-3;
  const RenderResult a = fh::render(dc, scene, bvh, scene.camera, s);
  s.wavefront = 256;
  const RenderResult b = fh::render(dc, scene, bvh, scene.camera, s);
  EXPECT_EQ(a.film.passes(), b.film.passes());
  EXPECT_EQ(a.film.sum, b.film.sum);
  EXPECT_LT(a.film.passes(), 4096u);
}

// The command line: the render says it met the target and the file carries the estimate;
// a negative or non-numeric target is a one-line error before any work.
TEST(NoiseCli, MeetsTheTargetAndWritesTheEstimate) {
  const std::string dir = test::tempDir("noise-cli");
  const auto r = test::runFredholm("render --width 24 --height 24 --noise 3e-3 -o " + dir + "/n.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("meets --noise 3.000e-03"), std::string::npos) << r.output;
  auto in = OIIO::ImageInput::open(dir + "/n.exr");
  ASSERT_TRUE(in);
  const double estimate = std::stod(in->spec().get_string_attribute("fredholm:estimated_relmse"));
  EXPECT_GT(estimate, 0.0);
  EXPECT_LE(estimate, 3e-3);
  for (const char* bad : {"-1", "abc"}) {
    const auto e = test::runFredholm(std::string("render --noise ") + bad + " -o " + dir + "/bad.exr");
    EXPECT_NE(e.exitCode, 0) << bad;
    EXPECT_NE(e.output.find("--noise"), std::string::npos) << e.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad.exr"));
  }
}

// A scene lit a thousand times more dimly meets the same --noise after fewer passes: its
// pixels' squares are far below relMSE's epsilon, so the estimate measures absolute error.
// The render says so, and the default scene's does not.
TEST(NoiseCli, ADimImageMeetingTheTargetSaysSo) {
  const std::string dir = test::tempDir("noise-dim");
  const std::string obj = test::projectScene("cornell-box/CornellBox-Original.obj");
  std::ifstream mtl(obj.substr(0, obj.size() - 4) + ".mtl");
  std::stringstream text;
  text << mtl.rdbuf();
  std::string dim = text.str();
  const size_t at = dim.find("Ke 17 12 4");
  ASSERT_NE(at, std::string::npos);
  dim.replace(at, 10, "Ke 0.017 0.012 0.004");
  test::writeFile(dir + "/CornellBox-Original.mtl", dim);
  std::filesystem::copy_file(obj, dir + "/dim.obj");
  const std::string flags = " --width 24 --height 24 --noise 3e-3 --spp 4096 --force -o ";
  const auto bright = test::runFredholm("render" + flags + dir + "/bright.exr");
  ASSERT_EQ(bright.exitCode, 0) << bright.output;
  EXPECT_EQ(bright.output.find("is dim"), std::string::npos) << bright.output;
  const auto dimmed = test::runFredholm("render " + dir + "/dim.obj" + flags + dir + "/dim.exr");
  ASSERT_EQ(dimmed.exitCode, 0) << dimmed.output;
  EXPECT_NE(dimmed.output.find("fredholm: warning: the image is dim (mean "), std::string::npos) << dimmed.output;
  EXPECT_NE(dimmed.output.find("measured absolute error (met after 16 passes)"), std::string::npos) << dimmed.output;
}

}  // namespace
}  // namespace fh
