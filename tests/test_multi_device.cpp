// Several devices sharing one render, on PoCL's two CPU devices (POCL_DEVICES is set
// before OpenCL loads): both devices work, the merged image is the single-device image
// (bitwise for one seed, statistically equal across seeds), deterministic, and a device
// that fails mid-render loses no work and counts none twice.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/test_hooks.h"
#include "render/render.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

struct TwoDevices : ::testing::Test {
  static void SetUpTestSuite() { setenv("POCL_DEVICES", "pthread pthread", 1); }
  std::vector<DeviceInfo> devices() {
    auto all = selectDevices(listDevices(), "all");
    if (all.size() < 2) ADD_FAILURE() << "POCL_DEVICES gave " << all.size() << " device(s)";
    return all;
  }
  Scene scene = loadDefaultScene();
  Bvh bvh = buildBvh(scene);
  RenderSettings settings = [] {
    RenderSettings s = test::renderSettings();
    s.width = s.height = 24;
    s.spp = 64;
    s.seed = 9;
    return s;
  }();
  // The render with `failure` in place (FREDHOLM_FAIL_DEVICE=I:N, base/test_hooks.h).
  RenderResult renderFailing(const std::vector<DeviceInfo>& on, TestHooks::DeviceFailure failure) {
    TestHooks hooks = testHooks();
    hooks.failDevice = failure;
    const ScopedTestHooks failing(hooks);
    return render(on, scene, bvh, scene.camera, settings);
  }
  // settings.method's image of the caustic scene, on one device, on two and in chunks.
  void expectSplatsMergeExactly();
};

TEST_F(TwoDevices, BothWorkAndTheMergeEqualsOneDevicesSamples) {
  const auto all = devices();
  ASSERT_GE(all.size(), 2u);
  const RenderResult multi = render(all, scene, bvh, scene.camera, settings);
  ASSERT_TRUE(multi.complete);
  EXPECT_EQ(multi.stats.samples, 24u * 24u * 64u);
  uint64_t total = 0;
  for (const auto& d : multi.stats.devices) {
    EXPECT_GT(d.samples, 0u) << d.name << " did no work";
    EXPECT_TRUE(d.error.empty()) << d.error;
    total += d.samples;
  }
  EXPECT_EQ(total, multi.stats.samples);

  // One render path: one device is a pool of one, merging the same global passes in the
  // same order and precision, so the image is the same to the last bit.
  const RenderResult one = render({all[0]}, scene, bvh, scene.camera, settings);
  EXPECT_EQ(one.stats.devices.size(), 1u);
  EXPECT_EQ(multi.film.sum, one.film.sum);
  EXPECT_EQ(multi.film.sumSq, one.film.sumSq);
}

TEST_F(TwoDevices, MergedImageMatchesAnIndependentSingleDeviceRender) {
  const auto all = devices();
  ASSERT_GE(all.size(), 2u);
  settings.spp = 128;
  const RenderResult multi = render(all, scene, bvh, scene.camera, settings);
  RenderSettings other = settings;
  other.seed = 10;
  const Film one = render({all[0]}, scene, bvh, scene.camera, other).film;
  // Image means over 4x4 blocks, z-tests with the two renders' own variances.
  double diff = 0, var = 0;
  int outliers = 0, blocks = 0;
  for (int by = 0; by < 6; ++by)
    for (int bx = 0; bx < 6; ++bx) {
      double d = 0, v = 0;
      for (int y = by * 4; y < by * 4 + 4; ++y)
        for (int x = bx * 4; x < bx * 4 + 4; ++x) {
          const size_t p = size_t(y * 24 + x);
          for (int c = 0; c < 3; ++c) {
            d += (multi.film.sum[4 * p + size_t(c)] / multi.film.count(p) - one.sum[4 * p + size_t(c)] / one.count(p)) / 48;
            v += (multi.film.varianceOfMean(p)[size_t(c)] + one.varianceOfMean(p)[size_t(c)]) / (48.0 * 48.0) * 3;
          }
        }
      diff += d;
      var += v;
      ++blocks;
      if (std::fabs(d) > 3.29 * std::sqrt(v)) ++outliers;
    }
  EXPECT_LT(std::fabs(diff / std::sqrt(var)), 4.0);
  EXPECT_LE(outliers, 2) << outliers << " of " << blocks << " blocks outside 3.29 sigma";
}

// Light tracing, bidirectional path tracing and vcm (whose merging radius follows the global
// pass) splat anywhere in the image, as whole film
// quanta added in 64-bit integers (render/light_tracer.h): one device, two devices, and a
// render in chunks merged all give the same bits. The caustic scene's glass adds camera paths
// to each of lt's passes too.
TEST_F(TwoDevices, LightTracingSplatsMergeToTheSameBitsOnAnyDevicesAndChunks) {
  for (Method method : {Method::LT, Method::BDPT, Method::VCM}) {
    SCOPED_TRACE(methodName(method));
    settings.method = method;
    expectSplatsMergeExactly();
  }
}

void TwoDevices::expectSplatsMergeExactly() {
  const auto all = devices();
  ASSERT_GE(all.size(), 2u);
  const Scene glass = loadScene(test::projectScene("failure/caustic.obj"));
  const Bvh glassBvh = buildBvh(glass);
  // Passes enough that the second device, starting a little later, still gets some: a pass
  // of bdpt's here takes about a millisecond.
  settings.spp = 48;
  const Film one = render({all[0]}, glass, glassBvh, glass.camera, settings).film;
  const RenderResult multi = render(all, glass, glassBvh, glass.camera, settings);
  for (const auto& d : multi.stats.devices) EXPECT_GT(d.samples, 0u) << d.name << " did no work";
  EXPECT_EQ(multi.film.sum, one.sum);
  RenderSettings first = settings, second = settings;
  first.spp = 20;  // passes 0..19
  second.firstPass = 20;
  Film chunks = render({all[1]}, glass, glassBvh, glass.camera, second).film;
  chunks.merge(render({all[0]}, glass, glassBvh, glass.camera, first).film);
  EXPECT_EQ(chunks.sum, one.sum);
  EXPECT_EQ(chunks.passes(), 48u);
  double total = 0;
  for (double v : one.sum) total += v;
  EXPECT_GT(total, 0.0);
}

TEST_F(TwoDevices, DeterministicForASeedAndDeviceList) {
  const auto all = devices();
  const RenderResult a = render(all, scene, bvh, scene.camera, settings);
  const RenderResult b = render(all, scene, bvh, scene.camera, settings);
  EXPECT_EQ(a.film.sum, b.film.sum);
  EXPECT_EQ(a.film.sumSq, b.film.sumSq);
}

// A noise target ends the render at the first pass count whose film meets it, whichever
// devices rendered the passes and however many more were in flight: the same image as on
// one device.
TEST_F(TwoDevices, ANoiseTargetStopsAtTheSamePassAsOneDevice) {
  const auto all = devices();
  ASSERT_GE(all.size(), 2u);
  settings.spp = 4096;
  settings.noise = 3e-3;
  const RenderResult multi = render(all, scene, bvh, scene.camera, settings);
  const RenderResult one = render({all[0]}, scene, bvh, scene.camera, settings);
  ASSERT_TRUE(multi.complete);
  EXPECT_GT(multi.film.passes(), uint64_t(kNoiseMinPasses));
  EXPECT_LT(multi.film.passes(), 4096u);
  EXPECT_LE(multi.film.estimatedRelMse(), settings.noise);
  EXPECT_EQ(multi.film.passes(), one.film.passes());
  EXPECT_EQ(multi.film.sum, one.film.sum);
}

TEST_F(TwoDevices, AFailingDeviceLosesNothingAndCountsNothingTwice) {
  const auto all = devices();
  const RenderResult reference = render(all, scene, bvh, scene.camera, settings);
  const RenderResult failed = renderFailing(all, {1, 3});
  ASSERT_TRUE(failed.complete);
  EXPECT_NE(failed.stats.devices[1].error.find("simulated failure"), std::string::npos);
  EXPECT_EQ(failed.stats.devices[1].samples, 3u * 24u * 24u);  // the passes it finished before failing
  EXPECT_EQ(failed.stats.samples, 24u * 24u * 64u);
  // Every pass exactly once: the same image as without the failure.
  EXPECT_EQ(failed.film.sum, reference.film.sum);
}

TEST_F(TwoDevices, WhenEveryDeviceFailsTheImageSoFarIsKept) {
  const auto all = devices();
  const RenderResult r = renderFailing({all[0]}, {0, 2});
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(r.stats.samples, 2u * 24u * 24u);
  for (size_t p = 0; p < 24u * 24u; ++p) EXPECT_EQ(r.film.count(p), 2.0) << p;
}

TEST(MultiDeviceCli, UnequalPairBothWorkAndStatsReportShares) {
  const std::string dir = test::tempDir("multi");
  // A first, small render compiles the kernels for both devices (kernel caches), so the
  // slow device is not still compiling while the fast one takes every pass.
  const std::string env = "POCL_DEVICES='basic pthread'";
  ASSERT_EQ(test::runFredholm("render --device all --width 16 --height 16 --spp 4 -o " + dir + "/warm.png", env)
                .exitCode,
            0);
  const auto r = test::runFredholm("render --device all --width 128 --height 128 --spp 64 -o " + dir +
                                       "/m.exr --stats " + dir + "/s.json",
                                   env);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto stats = test::readJson(dir + "/s.json");
  ASSERT_EQ(stats["devices"].size(), 2u);
  double shares = 0;
  for (const auto& d : stats["devices"]) {
    EXPECT_GT(d["samples"].get<uint64_t>(), 0u) << d;
    EXPECT_GT(d["samples_per_second"].get<double>(), 0.0) << d;
    EXPECT_TRUE(d.contains("idle_seconds")) << d;
    shares += d["share"].get<double>();
  }
  EXPECT_NEAR(shares, 1.0, 1e-9);
  EXPECT_EQ(stats["samples"], 128 * 128 * 64);
}

TEST(MultiDeviceCli, FailureIsReportedAndTheRenderFinishes) {
  const std::string dir = test::tempDir("multi");
  const auto r = test::runFredholm("render --device all --width 32 --height 32 --spp 16 -o " + dir + "/m.png",
                                   "POCL_DEVICES='pthread pthread' FREDHOLM_FAIL_DEVICE=1:2");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("fredholm: warning: device"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the other devices rendered its passes"), std::string::npos) << r.output;
}

// --device means the same in every command: render uses every device selected and names
// each that contributed (metadata, stats, summary); bench measures each, a row per device;
// --aov, which draws on one device, refuses a spec that selects several.
TEST(MultiDeviceCli, EveryCommandTakesEveryDeviceTheSpecSelects) {
  const std::string dir = test::tempDir("multi");
  const std::string env = "POCL_DEVICES='pthread basic'";
  // More passes than one device holds in flight (8), so the first device to start cannot
  // take them all before the other asks.
  const auto r = test::runFredholm(
      "render --device all --width 32 --height 32 --spp 64 -o " + dir + "/m.exr --stats " + dir + "/s.json", env);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  auto image = OIIO::ImageInput::open(dir + "/m.exr");
  ASSERT_TRUE(image);
  const std::string named = image->spec().get_string_attribute("fredholm:device");
  const auto stats = test::readJson(dir + "/s.json");
  ASSERT_EQ(stats["devices"].size(), 2u);
  for (const auto& d : stats["devices"]) {
    const std::string name = d["name"];
    EXPECT_NE(named.find(name), std::string::npos) << named << " lacks " << name;
    EXPECT_NE(r.output.find(name), std::string::npos) << "the summary line lacks " << name << ": " << r.output;
  }

  const auto bench = test::runFredholm(
      "bench cornell --device all --width 16 --height 16 --repeats 1 --json " + dir + "/b.json", env);
  ASSERT_EQ(bench.exitCode, 0) << bench.output;
  const auto doc = test::readJson(dir + "/b.json");
  ASSERT_EQ(doc["devices"].size(), 2u);
  for (const auto& device : doc["devices"]) {
    int rows = 0;
    for (const auto& record : doc["records"]) rows += record["device"] == device;
    EXPECT_EQ(rows, 3) << device << ": one row per ray kind (primary, bounce, shadow)";
  }
  // With Embree built in, the ratio is the median of the interleaved repeats' own ratios.
  if (!doc["external"].get<std::string>().empty())
    for (const auto& record : doc["records"]) {
      EXPECT_LE(record["ratio_to_embree_min"].get<double>(), record["ratio_to_embree"].get<double>());
      EXPECT_LE(record["ratio_to_embree"].get<double>(), record["ratio_to_embree_max"].get<double>());
    }

  const auto aov = test::runFredholm("render --aov albedo --device all -o " + dir + "/a.png", env);
  EXPECT_EQ(aov.exitCode, 1);
  EXPECT_NE(aov.output.find("fredholm: error: --aov renders on one device"), std::string::npos) << aov.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/a.png"));
  EXPECT_EQ(test::runFredholm("render --aov albedo --device 1 --width 8 --height 8 -o " + dir + "/b.png", env).exitCode,
            0);
}

}  // namespace
}  // namespace fh
