// Adaptive sampling (--adaptive, render/adaptive.h): the rounds' schedule, which pixels a
// round takes from a film, the film's per-pixel counts (its noise estimate, its file), and
// the command line: budget, determinism, resuming mid-round, refusals. Renders checked
// against closed forms with adaptive sampling are in test_path_tracer.cpp (every strategy).
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "render/adaptive.h"
#include "render/checkpoint.h"
#include "test_support.h"

namespace fh {
namespace {

TEST(AdaptiveRounds, ArePowersOfTwoLongAndAlignedToTheirLength) {
  const std::vector<uint32_t> expected = {0, 16, 32, 48, 64, 96, 128, 192, 256, 320, 384};
  uint32_t begin = 0;
  for (size_t i = 0; i + 1 < expected.size(); ++i) {
    ASSERT_EQ(begin, expected[i]);
    begin = adaptiveRoundEnd(begin);
  }
  for (begin = 0; begin < 100000; begin = adaptiveRoundEnd(begin)) {
    const uint32_t length = adaptiveRoundEnd(begin) - begin;
    EXPECT_EQ(length & (length - 1), 0u) << begin;  // a power of two ...
    EXPECT_EQ(begin % length, 0u) << begin;          // ... starting at a multiple of itself
    EXPECT_LE(length, kAdaptiveLongestRound);
    for (uint32_t pass : {begin, begin + length / 2, begin + length - 1}) EXPECT_EQ(adaptiveRoundBegin(pass), begin);
  }
}

// A film of `passes` passes over every pixel, each pixel's samples alternating between
// mean - spread and mean + spread (so its sample variance is about spread^2).
Film filmOf(int width, int height, uint32_t passes, const std::function<std::pair<float, float>(int, int)>& pixel) {
  Film film(width, height);
  std::vector<float> samples(size_t(width) * size_t(height) * 4);
  for (uint32_t pass = 0; pass < passes; ++pass) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const auto [mean, spread] = pixel(x, y);
        float* s = &samples[4 * (size_t(y) * size_t(width) + size_t(x))];
        s[0] = s[1] = s[2] = mean + (pass % 2 ? spread : -spread);
        s[3] = 1.f;
      }
    film.addPass(pass, samples);
  }
  return film;
}

// A film of fewer than kAdaptiveFirstRound passes is too little to choose from: every
// pixel, however noisy.
TEST(AdaptivePixels, AFilmOfLessThanTheFirstRoundChoosesEveryPixel) {
  for (uint32_t passes : {0u, kAdaptiveFirstRound - 1}) {
    const Film film = filmOf(64, 16, passes, [&](int x, int) { return std::make_pair(1.f, x < 8 ? 0.5f : 0.f); });
    EXPECT_EQ(adaptivePixels(film, kAdaptiveFirstRound, nullptr, kAdaptiveFirstRound), nullptr) << passes;
  }
}

// Eight noisy columns of 64, the rest exact: a round takes them and the two columns beside
// them (a pixel beside a noisy block goes with it), in ascending order.
TEST(AdaptivePixels, ARoundTakesTheNoisyPixelsAndTheirNeighbours) {
  const int w = 64, h = 16;
  const Film film = filmOf(w, h, 16, [&](int x, int) { return std::make_pair(1.f, x < 8 ? 0.5f : 0.f); });
  const auto pixels = adaptivePixels(film, 32, nullptr, 16);
  ASSERT_NE(pixels, nullptr);
  EXPECT_TRUE(std::is_sorted(pixels->begin(), pixels->end()));
  std::vector<char> chosen(film.pixels(), 0);
  for (uint32_t p : *pixels) chosen[p] = 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) EXPECT_EQ(bool(chosen[size_t(y * w + x)]), x < 10) << x << "," << y;
}

// The round before is counted as if in. Columns with 16 times the others' variance are
// chosen; were the round before to bring them to four times the others' samples, their
// error would fall as fast as the others' and the round would cover every pixel.
TEST(AdaptivePixels, TheSamplesOfTheRoundBeforeCount) {
  const int w = 64, h = 16;
  const Film film = filmOf(w, h, 16, [&](int x, int) { return std::make_pair(1.f, x < 8 ? 0.5f : 0.125f); });
  auto noisy = std::make_shared<PixelList>();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 8; ++x) noisy->push_back(uint32_t(y * w + x));
  const auto pixels = adaptivePixels(film, 32, noisy.get(), 0);
  ASSERT_NE(pixels, nullptr);
  for (int y = 0; y < h; ++y)
    for (int x : {0, 7, 16, 63})
      EXPECT_EQ(std::binary_search(pixels->begin(), pixels->end(), uint32_t(y * w + x)), x < 8) << x << "," << y;
  EXPECT_EQ(adaptivePixels(film, 64, noisy.get(), 48), nullptr);
}

// Noise everywhere alike: choosing would not pay, and the round covers every pixel.
TEST(AdaptivePixels, EvenNoiseKeepsEveryPixel) {
  const Film film =
      filmOf(32, 32, 16, [](int x, int y) { return std::make_pair(1.f, 0.3f + 0.01f * float((x + y) % 3)); });
  EXPECT_EQ(adaptivePixels(film, 32, nullptr, 16), nullptr);
}

// Noise in a few pixels only: the round still covers one pixel in kAdaptiveMinShare, the
// noisiest first (then by index), so its passes fill a wavefront.
TEST(AdaptivePixels, ARoundCoversAtLeastItsShareOfThePixels) {
  const int w = 64, h = 64;
  const Film film = filmOf(w, h, 16, [](int x, int y) {
    return std::make_pair(1.f, x == 10 && y == 10 ? 1.f : x < 32 ? 0.001f * float(y + 1) : 0.f);
  });
  const auto pixels = adaptivePixels(film, 32, nullptr, 16);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(pixels->size(), size_t(w * h) / kAdaptiveMinShare);
  EXPECT_TRUE(std::binary_search(pixels->begin(), pixels->end(), uint32_t(10 * w + 10)));
  // After the firefly's neighbourhood, the noisiest rows of the left half: the bottom ones.
  EXPECT_TRUE(std::binary_search(pixels->begin(), pixels->end(), uint32_t(63 * w + 0)));
  EXPECT_FALSE(std::binary_search(pixels->begin(), pixels->end(), uint32_t(20 * w + 0)));
  EXPECT_EQ(*adaptivePixels(film, 32, nullptr, 16), *pixels);  // the same film, the same round
}

// A pixel with no noise at all still gets samples once it has fewer than one in
// kAdaptiveMaxSpread of the busiest pixel's, so every pixel converges.
TEST(AdaptivePixels, NoPixelFallsTooFarBehind) {
  const int w = 16, h = 16;
  Film film = filmOf(w, h, 16, [](int, int) { return std::make_pair(1.f, 0.f); });
  std::vector<float> samples(film.pixels() * 4, 0.f);
  samples[3] = 1.f;  // pixel 0 alone, noisy
  for (uint32_t pass = 16; pass < 16 * kAdaptiveMaxSpread; ++pass) {
    samples[0] = samples[1] = samples[2] = pass % 2 ? 2.f : 0.f;
    film.addPass(pass, samples);
  }
  auto pixels = adaptivePixels(film, 16 * kAdaptiveMaxSpread, nullptr, 0);
  ASSERT_NE(pixels, nullptr);
  // 16 of 256 samples: not yet behind. The round is pixel 0's neighbourhood alone (fewer
  // than kAdaptiveMinShare: no pixel without noise is taken to fill it).
  EXPECT_EQ(pixels->size(), 9u);
  EXPECT_EQ(pixels->front(), 0u);
  EXPECT_FALSE(std::binary_search(pixels->begin(), pixels->end(), uint32_t(film.pixels() - 1)));
  samples[0] = samples[1] = samples[2] = 1.f;
  film.addPass(16 * kAdaptiveMaxSpread, samples);
  EXPECT_EQ(adaptivePixels(film, 16 * kAdaptiveMaxSpread + 1, nullptr, 0), nullptr) << "16 of 257 samples: all are behind";
  // The same where the round before is to bring pixel 0 to 257 samples.
  pixels = adaptivePixels(film, 16 * kAdaptiveMaxSpread, std::make_shared<PixelList>(PixelList{0}).get(), 1);
  EXPECT_EQ(pixels, nullptr);
}

// Each pixel's noise estimate counts its own even and odd samples: pixel 1, in passes 0-2
// only, has two even samples and one odd where the film has eight of each.
TEST(AdaptiveFilm, TheNoiseEstimateCountsEachPixelsOwnSamples) {
  Film film(2, 1, false, true);
  for (uint32_t pass = 0; pass < 16; ++pass) {
    const float v = pass % 2 ? 0.6f : 0.4f, second = pass < 3 ? 1.f : 0.f;
    film.addPass(pass, {v, v, v, 1.f, v * second, v * second, v * second, second});
  }
  EXPECT_EQ(film.count(0), 16.0);
  EXPECT_EQ(film.count(1), 3.0);
  EXPECT_EQ(film.oddSum[kOddSumsPerPixel * 0 + 3], 8.0);
  EXPECT_EQ(film.oddSum[kOddSumsPerPixel * 1 + 3], 1.0);
  // Per pixel: D^2 nEven nOdd / n^2 over the neighbours' mean^2 + epsilon (here the other
  // pixel's), D the halves' means' difference.
  const double mean0 = 0.5, mean1 = (0.4 + 0.6 + 0.4) / 3;
  const double pixel0 = 0.04 * 8 * 8 / 256 / (mean1 * mean1 + 0.01), pixel1 = 0.04 * 2 * 1 / 9 / (mean0 * mean0 + 0.01);
  EXPECT_NEAR(film.estimatedRelMse(), (pixel0 + pixel1) / 2, 1e-6);
}

// A film saved mid-round keeps the pixels of its round and of the next, and a file whose
// list is not ascending pixel indices is refused.
TEST(AdaptiveFilm, TheRoundsPixelsGoInTheFile) {
  const std::string dir = test::tempDir("adaptive-film");
  Film film = filmOf(4, 4, 16, [](int x, int) { return std::make_pair(1.f, 0.1f * float(x)); });
  film.roundPixels = std::make_shared<PixelList>(PixelList{1, 2, 5, 9});
  film.nextRoundPixels = std::make_shared<PixelList>(PixelList{0, 3, 15});
  saveFilm(dir + "/f.film", film, "abc", "--film");
  const SavedFilm back = readFilm(dir + "/f.film", "--film");
  ASSERT_NE(back.film.roundPixels, nullptr);
  ASSERT_NE(back.film.nextRoundPixels, nullptr);
  EXPECT_EQ(*back.film.roundPixels, *film.roundPixels);
  EXPECT_EQ(*back.film.nextRoundPixels, *film.nextRoundPixels);
  EXPECT_EQ(back.film.sum, film.sum);
  film.roundPixels = std::make_shared<PixelList>(PixelList{2, 1});
  saveFilm(dir + "/g.film", film, "abc", "--film");
  try {
    readFilm(dir + "/g.film", "--film");
    FAIL() << "a pixel list out of order was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a fredholm film"), std::string::npos) << e.what();
  }
}

// A channel of an EXR, by name (empty if it has none).
std::vector<float> layer(const std::string& path, const std::string& name) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {};
  const OIIO::ImageSpec spec = in->spec();
  const int channel = spec.channelindex(name);
  std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data());
  std::vector<float> spp;
  for (size_t p = 0; channel >= 0 && p < all.size() / size_t(spec.nchannels); ++p)
    spp.push_back(all[p * size_t(spec.nchannels) + size_t(channel)]);
  return spp;
}

// The caustic scene: most of its noise is in the caustic and the glass, where rounds go.
const std::string kAdaptive = "render " + test::projectScene("failure/caustic.obj") +
                              " --width 32 --height 32 --spp 48 --seed 5 --adaptive --aovs spp";

// --spp is the image's average, a budget it does not exceed; pixels get from 16 to many
// more. The surface layers count each pixel's own samples too: an albedo above one would
// be a pass's stale entries added where it did not cover the pixel.
TEST(AdaptiveCli, SpendsTheBudgetUnevenly) {
  const std::string dir = test::tempDir("adaptive-cli");
  const auto r = test::runFredholm(kAdaptive + ",albedo -o " + dir + "/a.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::vector<float> albedo = layer(dir + "/a.exr", "albedo.G");
  ASSERT_EQ(albedo.size(), 32u * 32u);
  EXPECT_LE(*std::max_element(albedo.begin(), albedo.end()), 1.f);
  EXPECT_GT(*std::max_element(albedo.begin(), albedo.end()), 0.5f);
  const std::vector<float> spp = layer(dir + "/a.exr", "spp.Y");
  ASSERT_EQ(spp.size(), 32u * 32u);
  double total = 0;
  for (float n : spp) total += n;
  EXPECT_LE(total, 48.0 * 32 * 32);
  EXPECT_GT(total, 40.0 * 32 * 32) << "most of the budget is spent";
  EXPECT_EQ(*std::min_element(spp.begin(), spp.end()), float(kAdaptiveFirstRound)) << "the first round";
  EXPECT_GT(*std::max_element(spp.begin(), spp.end()), 64.f);
  EXPECT_NE(r.output.find(" spp on "), std::string::npos) << r.output;
}

// The image for a seed is the same bits on two devices (PoCL's two) as on one, and with a
// wavefront of 64 paths: rounds are chosen from films merged in pass order.
TEST(AdaptiveCli, TheImageForASeedIsTheSameOnEveryDeviceAndWavefront) {
  const std::string dir = test::tempDir("adaptive-same");
  ASSERT_EQ(test::runFredholm(kAdaptive + " -o " + dir + "/one.exr").exitCode, 0);
  const auto two = test::runFredholm(kAdaptive + " --device all -o " + dir + "/two.exr",
                                     "POCL_DEVICES='pthread basic'");
  ASSERT_EQ(two.exitCode, 0) << two.output;
  ASSERT_EQ(test::runFredholm(kAdaptive + " --wavefront 64 -o " + dir + "/small.exr").exitCode, 0);
  const Image one = readImage(dir + "/one.exr");
  EXPECT_TRUE(readImage(dir + "/two.exr").rgb == one.rgb);
  EXPECT_TRUE(readImage(dir + "/small.exr").rgb == one.rgb);
  EXPECT_EQ(layer(dir + "/two.exr", "spp.Y"), layer(dir + "/one.exr", "spp.Y"));
}

// A pixel's samples are the first points of its sequence, however many rounds passed it by
// (render/pass_source.h, RoundPixels): where the adaptive render gave a pixel n samples, its
// value is the same bits as a uniform render's of n samples per pixel (the same seed: the
// same points, and the film's sums do not depend on the order). Checked for the three
// counts above the first round's that most pixels have.
TEST(AdaptiveCli, EachPixelsSamplesAreTheFirstPointsOfItsSequence) {
  const std::string dir = test::tempDir("adaptive-prefix");
  ASSERT_EQ(test::runFredholm(kAdaptive + " -o " + dir + "/a.exr").exitCode, 0);
  const Image adaptive = readImage(dir + "/a.exr");
  const std::vector<float> spp = layer(dir + "/a.exr", "spp.Y");
  std::map<int, int> pixelsWith;
  for (float n : spp)
    if (n > float(kAdaptiveFirstRound)) ++pixelsWith[int(n)];
  std::vector<std::pair<int, int>> common;  // (pixels, count), most pixels first
  for (const auto& [count, pixels] : pixelsWith) common.push_back({pixels, count});
  std::sort(common.rbegin(), common.rend());
  ASSERT_GE(common.size(), 3u) << "the rounds gave pixels a few different counts";
  for (size_t i = 0; i < 3; ++i) {
    const int count = common[i].second;
    const std::string out = dir + "/u" + std::to_string(count) + ".exr";
    ASSERT_EQ(test::runFredholm("render " + test::projectScene("failure/caustic.obj") + " --width 32 --height 32 --spp " +
                                std::to_string(count) + " --seed 5 -o " + out).exitCode, 0);
    const Image uniform = readImage(out);
    int differ = 0;
    for (size_t p = 0; p < spp.size(); ++p)
      if (int(spp[p]) == count)
        for (size_t c = 0; c < 3; ++c) differ += adaptive.rgb[3 * p + c] != uniform.rgb[3 * p + c];
    EXPECT_EQ(differ, 0) << "of the " << common[i].first << " pixels with " << count << " samples";
  }
}

// Killed at the start of a round, in the first round and in later ones, and resumed: the
// checkpoint says which pixels its round covers, and the image is the uninterrupted one's.
TEST(AdaptiveCli, AResumedRenderFinishesItsRound) {
  const std::string dir = test::tempDir("adaptive-resume");
  ASSERT_EQ(test::runFredholm(kAdaptive + " -o " + dir + "/straight.exr").exitCode, 0);
  const Image straight = readImage(dir + "/straight.exr");
  for (const char* passes : {"10", "16", "21", "26", "32", "70", "85"}) {
    const std::string ckpt = dir + "/c" + passes + ".fhc", out = dir + "/r" + passes + ".exr";
    const auto killed = test::runFredholm(kAdaptive + " --checkpoint " + ckpt + " --checkpoint-every 0 -o " + out,
                                          std::string("FREDHOLM_KILL_AFTER_PASSES=") + passes);
    EXPECT_NE(killed.exitCode, 0) << passes;
    ASSERT_TRUE(std::filesystem::exists(ckpt)) << passes << ": " << killed.output;
    const auto resumed = test::runFredholm(kAdaptive + " --resume " + ckpt + " -o " + out);
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_TRUE(readImage(out).rgb == straight.rgb) << "resumed after " << passes << " passes";
  }
  // A render that did not adapt is another render.
  ASSERT_EQ(test::runFredholm("render " + test::projectScene("failure/caustic.obj") +
                              " --width 32 --height 32 --spp 20 --seed 5 --checkpoint " + dir + "/u.fhc -o " + dir +
                              "/u.exr").exitCode, 0);
  const auto other = test::runFredholm(kAdaptive + " --resume " + dir + "/u.fhc -o " + dir + "/x.exr");
  EXPECT_NE(other.exitCode, 0);
  EXPECT_NE(other.output.find("fredholm: error:"), std::string::npos) << other.output;
}

// With a noise target: the render stops when the film's estimate (each pixel's own counts)
// meets it, and says so.
TEST(AdaptiveCli, StopsAtANoiseTarget) {
  const std::string dir = test::tempDir("adaptive-noise");
  const auto r = test::runFredholm("render --width 24 --height 24 --adaptive --noise 3e-3 -o " + dir + "/n.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("meets --noise"), std::string::npos) << r.output;
}

TEST(AdaptiveCli, WhatItDoesNotGoWithIsAOneLineError) {
  const std::string dir = test::tempDir("adaptive-refused");
  for (const std::string& flags :
       {std::string("--passes 0:32 --film ") + dir + "/f.film", std::string("--aov albedo")}) {
    const auto r = test::runFredholm("render --width 8 --height 8 --adaptive " + flags + " -o " + dir + "/x.exr");
    EXPECT_NE(r.exitCode, 0) << flags;
    EXPECT_EQ(r.output.rfind("fredholm: error:", 0), 0u) << r.output;
    EXPECT_NE(r.output.find("--adaptive"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  }
}

}  // namespace
}  // namespace fh
