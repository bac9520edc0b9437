// --method auto: the rule that picks from the pilots' costs, the methods a scene is piloted
// with, and the command line: the scenes the failure suite names get the method that is
// known to win there (mis on the Cornell box, whose light every method finds; light paths
// on the caustic scene, whose caustic camera paths find by chance), the image is the chosen
// method's for the seed, and what auto cannot do is a one-line error before any work.
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <random>
#include <string>

#include "cli/flags.h"
#include "image/error_metrics.h"
#include "image/image_io.h"
#include "render/method_choice.h"
#include "scene/environment_map.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

std::vector<MethodTrial> trials(double pt, double nee, double mis, double lt) {
  // Costs as relMSE x seconds, one second each.
  return {{Method::PT, 1.0, pt}, {Method::NEE, 1.0, nee}, {Method::MIS, 1.0, mis}, {Method::LT, 1.0, lt}};
}

TEST(MethodChoice, AnotherMethodMustBeatMisByTheMargin) {
  EXPECT_EQ(cheapestMethod(trials(9.0, 0.85, 1.0, 2.0)), Method::MIS);  // nee ahead, within a pilot's error
  EXPECT_EQ(cheapestMethod(trials(9.0, 0.79, 1.0, 2.0)), Method::NEE);
  EXPECT_EQ(cheapestMethod(trials(9.0, 1.1, 1.0, 0.3)), Method::LT);
  EXPECT_EQ(cheapestMethod(trials(0.2, 1.1, 1.0, 0.3)), Method::PT);   // the cheapest, not the first below
  EXPECT_EQ(cheapestMethod(trials(0.0, 0.0, 0.0, 0.0)), Method::MIS);  // a black image: no error to compare
  EXPECT_EQ(cheapestMethod({}), Method::MIS);                          // stopped before any pilot
  // The time counts as much as the error: half the error at three times the time loses.
  EXPECT_EQ(cheapestMethod({{Method::MIS, 1.0, 1.0}, {Method::LT, 3.0, 0.5}}), Method::MIS);
}

// A pilot image: `truth` with Gaussian noise of relative deviation `sigma`, from `seed`.
Image noisy(const Image& truth, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Image p = truth;
  for (float& v : p.rgb) v = float(v * (1.0 + sigma * normal(rng)));
  return p;
}

// relMSE of `image` against the truth, as fredholm compare measures it.
double relMseAgainst(const Image& image, const Image& truth) {
  double total = 0.0;
  for (size_t v = 0; v < truth.rgb.size(); ++v) {
    const double d = double(image.rgb[v]) - truth.rgb[v];
    total += d * d / (double(truth.rgb[v]) * truth.rgb[v] + kRelMseEpsilon);
  }
  return total / double(truth.rgb.size());
}

Image gradient(int side) {
  Image truth;
  truth.width = truth.height = side;
  for (int p = 0; p < side * side; ++p)
    for (int c = 0; c < 3; ++c) truth.rgb.push_back(0.2f + 0.8f * float(p % side) / float(side) + 0.1f * float(c));
  return truth;
}

// Three pilots of known error: the pairs' differences give each one's error, whatever the
// pilots claim; two pilots give each one's error once the other's is known.
TEST(MethodChoice, PilotsJudgeEachOtherFromTheirDifferences) {
  const Image truth = gradient(128);
  const std::vector<Image> pilots = {noisy(truth, 0.1, 1), noisy(truth, 0.15, 2), noisy(truth, 0.3, 3)};
  std::vector<double> actual;
  for (const Image& p : pilots) actual.push_back(relMseAgainst(p, truth));
  const std::vector<double> cross = crossRelMse(pilots, {0.0, 0.0, 0.0});  // three: own estimates unused
  for (size_t i = 0; i < pilots.size(); ++i) EXPECT_NEAR(cross[i], actual[i], 0.1 * actual[i]) << i;
  const std::vector<double> two = crossRelMse({pilots[0], pilots[2]}, {actual[0], actual[2]});
  EXPECT_NEAR(two[0], actual[0], 0.1 * actual[0]);
  EXPECT_NEAR(two[1], actual[2], 0.1 * actual[2]);
  EXPECT_EQ(crossRelMse({pilots[0]}, {actual[0]}), std::vector<double>{0.0});  // nothing to compare with
}

// A heavy-tailed method's pilot that found none of its rare bright paths is smooth, and its
// own halves agree: by its own estimate it wins. The other pilots have those paths, and judged
// by them it is far off: mis stays. Where the others agree with the own estimates, the
// choice is the own estimates'.
TEST(MethodChoice, APilotMissingRarePathsIsJudgedByTheOthers) {
  Image truth = gradient(96);
  // A caustic: bright 4x4 spots, one in every 16x16 pixels.
  const auto spot = [](size_t v) { return (v / 3) % 96 % 16 < 4 && (v / 3) / 96 % 16 < 4; };
  for (size_t v = 0; v < truth.rgb.size(); ++v)
    if (spot(v)) truth.rgb[v] = 40.0f;
  Image blind = noisy(truth, 0.01, 4);
  for (size_t v = 0; v < truth.rgb.size(); ++v)
    if (spot(v)) blind.rgb[v] = 1.0f;  // never found
  const std::vector<Image> images = {noisy(truth, 0.1, 5), blind, noisy(truth, 0.15, 6)};
  std::vector<MethodTrial> pilots = {{Method::MIS, 1.0, relMseAgainst(images[0], truth)},
                                     {Method::LT, 1.0, 1e-4},
                                     {Method::BDPT, 1.0, relMseAgainst(images[2], truth)}};
  EXPECT_EQ(cheapestMethod(pilots), Method::LT);  // by their own estimates
  judgePilots(pilots, images);
  EXPECT_GT(pilots[1].crossRelMse, 0.5 * relMseAgainst(blind, truth));
  EXPECT_EQ(cheapestMethod(pilots), Method::MIS);
  // A method that is better by both estimates is chosen: the same pilots, but lt's image
  // found the spots too.
  std::vector<Image> seeing = images;
  seeing[1] = noisy(truth, 0.01, 4);
  judgePilots(pilots, seeing);
  EXPECT_LT(pilots[1].crossRelMse, 0.2 * pilots[0].crossRelMse);
  EXPECT_EQ(cheapestMethod(pilots), Method::LT);
}

// Both estimates must clear the margin: a method ahead by its own estimate but level with mis
// in the others' stays behind mis, and one ahead in the others' alone too.
TEST(MethodChoice, AnotherMethodMustBeatMisInBothEstimates) {
  std::vector<MethodTrial> t = {{Method::MIS, 1.0, 1.0, 64, 1.0}, {Method::BDPT, 1.0, 0.5, 64, 0.9}};
  EXPECT_EQ(cheapestMethod(t), Method::MIS);
  t[1].crossRelMse = 0.5;
  EXPECT_EQ(cheapestMethod(t), Method::BDPT);
  t[1].relMse = 0.9;
  EXPECT_EQ(cheapestMethod(t), Method::MIS);
  // Not judged (no other pilot to compare with): the own estimates decide.
  t = {{Method::MIS, 1.0, 1.0}, {Method::BDPT, 1.0, 0.5}};
  EXPECT_EQ(cheapestMethod(t), Method::BDPT);
}

// mis's pilot samples go to the image's size, at kMinPilotSpp passes, up to the largest side.
TEST(MethodChoice, ALongerRenderGetsALargerPilot) {
  EXPECT_EQ(pilotSide(1000.0, 512), kMinPilotSide);  // a render of a moment: the smallest pilot
  EXPECT_EQ(pilotSide(double(kMinPilotSpp) * 80 * 80, 512), 80);
  EXPECT_EQ(pilotSide(300.0 * kMaxPilotSide * kMaxPilotSide, 512), kMaxPilotSide);
  EXPECT_EQ(pilotSide(1e12, 20), 20);  // never larger than the image
  EXPECT_EQ(pilotSide(1e3, 20), 20);
}

// Pilots are of equal time, so a slow method's is short of passes: its time budget, however
// soon spent, leaves it the passes of a noise estimate (RenderSettings::minPasses), and a
// render without that floor still renders one pass.
TEST(MethodChoice, APilotRendersItsLeastPassesHoweverShortItsTime) {
  const Scene scene = loadDefaultScene();
  RenderSettings s = test::renderSettings();
  s.width = s.height = 8;
  s.spp = 1000;
  s.seconds = 1e-9;
  s.minPasses = kNoiseMinPasses;
  EXPECT_EQ(test::render(scene, scene.camera, s).film.passes(), kNoiseMinPasses);
  s.minPasses = 1;
  EXPECT_EQ(test::render(scene, scene.camera, s).film.passes(), 1u);
}

TEST(MethodChoice, LightPathsArePilotedWhereTheyCanRenderTheScene) {
  const Scene cornell = loadDefaultScene();
  RenderSettings s;
  EXPECT_EQ(methodsFor(cornell, s), (std::vector<Method>{Method::MIS, Method::LT, Method::BDPT}));
  const std::vector<Method> cameraOnly = {Method::MIS};
  // An environment: bdpt's camera subpaths find it, light tracing's paths cannot.
  RenderSettings env = s;
  env.env = {0.1f, 0.1f, 0.1f};
  EXPECT_EQ(methodsFor(cornell, env), (std::vector<Method>{Method::MIS, Method::BDPT}));
  RenderSettings adaptive = s;
  adaptive.adaptive = true;
  EXPECT_EQ(methodsFor(cornell, adaptive), cameraOnly);
  RenderSettings layers = s;
  layers.surfaceAovs = true;
  EXPECT_EQ(methodsFor(cornell, layers), cameraOnly);
  // Lit by a constant environment alone: nothing to sample as a light, and pt is piloted.
  Scene dark = cornell;
  dark.lights.clear();
  EXPECT_EQ(methodsFor(dark, env), (std::vector<Method>{Method::PT, Method::MIS}));
  // Lit by a map alone: bdpt's light subpaths start on it.
  RenderSettings map = s;
  map.envMap = std::make_shared<EnvironmentMap>();
  EXPECT_EQ(methodsFor(dark, map), (std::vector<Method>{Method::MIS, Method::BDPT}));
  // Glass: vcm, which merges there, in bdpt's place.
  const Scene caustic = loadScene(test::projectScene("failure/caustic.obj"));
  EXPECT_EQ(methodsFor(caustic, s), (std::vector<Method>{Method::MIS, Method::LT, Method::VCM}));
}

struct AutoRender {
  test::CommandResult run;
  nlohmann::json stats;
  std::string image;
};

// The budget: a render long enough for pilots (a fifth of it holds the smallest).
AutoRender renderAuto(const std::string& scene, const std::string& flags, const std::string& budget = "--spp 256") {
  const std::string dir = test::tempDir("auto");
  AutoRender r;
  r.image = dir + "/auto.exr";
  r.run = test::runFredholm("render " + scene + " --method auto --width 128 --height 128 " + budget + " -o " + r.image +
                            " --stats " + dir + "/stats.json " + flags);
  if (r.run.exitCode == 0) r.stats = test::readJson(dir + "/stats.json");
  return r;
}

// The choice in --stats, in the image's metadata and on stderr, made by the rule above from the
// pilots' own figures.
void expectChoice(const AutoRender& r, const std::string& method, size_t methods) {
  ASSERT_EQ(r.run.exitCode, 0) << r.run.output;
  const nlohmann::json& choice = r.stats["method_choice"];
  EXPECT_EQ(choice["chosen"], method) << choice.dump(2);
  EXPECT_EQ(r.stats["method"], method);
  ASSERT_EQ(choice["methods"].size(), methods) << choice.dump(2);
  std::vector<MethodTrial> pilots;
  EXPECT_TRUE(choice["piloted"].get<bool>());
  EXPECT_GT(choice["pilot_seconds"].get<double>(), 0.0);
  for (const auto& [name, trial] : choice["methods"].items()) {
    EXPECT_GT(trial["relmse"].get<double>(), 0.0) << name;
    EXPECT_GT(trial["seconds"].get<double>(), 0.0) << name;
    // However short the render, each pilot has the smallest pilot's samples at least.
    const unsigned passes = trial["passes"];
    EXPECT_GE(passes, kNoiseMinPasses) << name;
    EXPECT_LE(passes, unsigned(kMaxPilotSpp)) << name;
    EXPECT_GE(double(passes) * choice["pilot_width"].get<int>() * choice["pilot_height"].get<int>(),
              double(kMinPilotSide) * kMinPilotSide * kMinPilotSpp)
        << name;
    EXPECT_GT(trial["cross_relmse"].get<double>(), 0.0) << name;  // judged by the others
    pilots.push_back({parseMethod(name), trial["seconds"], trial["relmse"], passes, trial["cross_relmse"]});
  }
  EXPECT_EQ(methodName(cheapestMethod(pilots)), method);
  EXPECT_NE(r.run.output.find("--method auto chose " + method + " ("), std::string::npos) << r.run.output;
  auto in = OIIO::ImageInput::open(r.image);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("fredholm:method"), method);
  EXPECT_NE(in->spec().get_string_attribute("fredholm:method_choice").find("relMSE x seconds"), std::string::npos);
}

TEST(MethodChoiceCli, TheCornellBoxGetsMis) {
  expectChoice(renderAuto(test::projectScene("cornell-box/CornellBox-Original.obj"), ""), "mis", 3);
}

// The caustic is carried by light paths: light tracing's lead over mis shows in a pilot of
// full size (a render of a few seconds gets one; in a small one its passes are too short to
// pay for their start). lt and vcm (bdpt's place, with glass) are close there, so either
// may win.
TEST(MethodChoiceCli, TheCausticSceneGetsLightPaths) {
  const AutoRender r = renderAuto(test::projectScene("failure/caustic.obj"), "", "--time 8");
  ASSERT_EQ(r.run.exitCode, 0) << r.run.output;
  const std::string chosen = r.stats["method_choice"]["chosen"];
  EXPECT_TRUE(chosen == "lt" || chosen == "vcm") << r.stats["method_choice"].dump(2);
  expectChoice(r, chosen, 3);
}

// A render so short that even the smallest pilots would take more than a fifth of it cannot
// gain from them: it is mis's, and says so.
TEST(MethodChoiceCli, ARenderTooShortForPilotsIsMisWithoutThem) {
  const AutoRender r = renderAuto(test::projectScene("failure/caustic.obj"), "", "--spp 1");
  ASSERT_EQ(r.run.exitCode, 0) << r.run.output;
  const nlohmann::json& choice = r.stats["method_choice"];
  EXPECT_EQ(choice["chosen"], "mis");
  EXPECT_EQ(r.stats["method"], "mis");
  EXPECT_FALSE(choice["piloted"].get<bool>());
  EXPECT_TRUE(choice["methods"].empty()) << choice.dump(2);
  EXPECT_GT(choice["least_pilot_seconds"].get<double>(), kMostPilotShare * choice["render_seconds"].get<double>());
  EXPECT_NE(r.run.output.find("--method auto chose mis without pilots: the smallest would take about "),
            std::string::npos)
      << r.run.output;
}

// Where mis is the only method the settings allow (light paths take neither adaptive passes
// nor first-surface layers), auto renders with it at once: nothing to time or pilot, however
// long the render.
TEST(MethodChoiceCli, WhereMisIsTheOnlyMethodNothingIsPiloted) {
  for (const std::string flags : {"--adaptive", "--aovs albedo,normal"}) {
    const AutoRender r = renderAuto(test::projectScene("failure/caustic.obj"), flags);
    ASSERT_EQ(r.run.exitCode, 0) << flags << ": " << r.run.output;
    const nlohmann::json& choice = r.stats["method_choice"];
    EXPECT_EQ(choice["chosen"], "mis") << flags;
    EXPECT_EQ(r.stats["method"], "mis") << flags;
    EXPECT_EQ(choice["candidates"], nlohmann::json::array({"mis"})) << flags << ": " << choice.dump(2);
    EXPECT_FALSE(choice["piloted"].get<bool>()) << flags;
    EXPECT_TRUE(choice["methods"].empty()) << flags << ": " << choice.dump(2);
    EXPECT_EQ(choice["render_seconds"].get<double>(), 0.0) << flags << ": mis was timed for nothing";
    EXPECT_EQ(r.run.output.find("a pilot render with each of"), std::string::npos) << r.run.output;
    EXPECT_NE(r.run.output.find("--method auto chose mis without pilots: the only method for these settings"),
              std::string::npos)
        << r.run.output;
  }
}

// With a constant environment nothing starts at the lights alone: no lt pilot; bdpt's
// camera subpaths find the environment.
TEST(MethodChoiceCli, AnEnvironmentLeavesLightTracingOut) {
  const AutoRender r = renderAuto(test::projectScene("cornell-box/CornellBox-Original.obj"), "--env 0.2,0.2,0.2");
  ASSERT_EQ(r.run.exitCode, 0) << r.run.output;
  EXPECT_EQ(r.stats["method_choice"]["methods"].size(), 2u);
  EXPECT_FALSE(r.stats["method_choice"]["methods"].contains("lt"));
  EXPECT_TRUE(r.stats["method_choice"]["methods"].contains("bdpt"));
}

// The pilots are apart from the render: its image is the chosen method's for the seed.
TEST(MethodChoiceCli, TheImageIsTheChosenMethodsImageForTheSeed) {
  const std::string scene = test::projectScene("failure/caustic.obj");
  const AutoRender r = renderAuto(scene, "--seed 5");
  ASSERT_EQ(r.run.exitCode, 0) << r.run.output;
  const std::string method = r.stats["method"];
  const std::string dir = test::tempDir("auto");
  const auto plain = test::runFredholm("render " + scene + " --method " + method +
                                       " --width 128 --height 128 --spp 256 --seed 5 -o " + dir + "/plain.exr");
  ASSERT_EQ(plain.exitCode, 0) << plain.output;
  EXPECT_EQ(readImage(r.image).rgb, readImage(dir + "/plain.exr").rgb) << method;
}

TEST(MethodChoiceCli, WhatAutoCannotGoWithIsAnErrorBeforeAnyWork) {
  const std::string dir = test::tempDir("auto");
  const std::string scene = test::projectScene("cornell-box/CornellBox-Original.obj");
  const std::pair<std::string, std::string> cases[] = {
      {"--passes 0:4 --film " + dir + "/chunk.film", "--passes (every chunk must have the method of the others)"},
      {"--resume " + dir + "/none.film", "--resume (the checkpoint's render chose its method already"},
      {"--aov albedo", "--aov (a debug view has no method)"}};
  for (const auto& [flags, why] : cases) {
    const auto r = test::runFredholm("render " + scene + " --method auto --width 8 --height 8 -o " + dir +
                                     "/x.exr " + flags);
    EXPECT_NE(r.exitCode, 0) << flags;
    EXPECT_NE(r.output.find("fredholm: error: --method auto chooses a method per render and does not go with " + why),
              std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("pilot"), std::string::npos) << "work began: " << r.output;
  }
}

}  // namespace
}  // namespace fh
