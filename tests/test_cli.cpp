// The render command as a user runs it: flags, errors, the --stats file, time budgets.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>
#include <vector>
#include <nlohmann/json.hpp>

#include "image/image_io.h"
#include "render/film.h"
#include "test_support.h"

namespace fh {
namespace {

TEST(RenderCli, BadFlagsAreOneLineErrorsBeforeAnyWork) {
  const std::string dir = test::tempDir("cli");
  const std::pair<const char*, const char*> cases[] = {
      {"--method foo", "--method 'foo': unknown method (use pt, nee, mis, lt, bdpt, vcm or auto)"},
      {"--filter tent", "--filter 'tent': unknown filter"},
      {"--env 1,1,x", "--env '1,1,x': 'x' is not a number"},
      {"--env 1e39,1,1", "--env '1e39,1,1': '1e39' is beyond the float range"},
      {"--aov shiny", "--aov 'shiny': unknown output"},
      {"--eye 0,1", "--eye '0,1': expected three comma-separated numbers"},
      {"--width 0", "--width/--height must be positive"},
      {"--max-depth 0", "--max-depth must be at least 1"},
      {"--fov 0", "--fov: vertical field of view must lie in (0, 180) degrees"},
      {"--width 100000 --height 100000", "is more than the 268 million pixels"},
      {"--camera /nonexistent/cam.json", "--camera '/nonexistent/cam.json': file not found"},
      {"/nonexistent/scene.obj", "scene '/nonexistent/scene.obj': file not found"},
      // Values a hostile user tried: negative radiance, non-finite and zero budgets, repeats.
      {"--env=-1,0,0", "--env '-1,0,0': radiance cannot be negative"},
      {"--time nan", "--time must be a finite number of seconds"},
      {"--time inf", "--time must be a finite number of seconds"},
      {"--spp 0", "--spp must be at least 1"},
      {"--wavefront 0", "--wavefront must be at least 64"},
      {"--spp 1 --spp 2", "fredholm: error: --spp"},
      // The strategy and roulette flags.
      {"--strategy vector",
       "--strategy 'vector': unknown strategy (use auto, scalar, simd8, megakernel or megakernel8)"},
      {"--rr-depth 0", "--rr-depth must be at least 1"},
      // vcm's merging radius: a fraction of the scene's, and vcm's alone.
      {"--method vcm --merge-radius 0", "--merge-radius must be a fraction of the scene's radius, from 1e-4 to 1"},
      {"--method vcm --merge-radius 1e-5", "--merge-radius must be a fraction of the scene's radius"},
      {"--method vcm --merge-radius nan", "--merge-radius must be a fraction of the scene's radius"},
      {"--method vcm --merge-radius 1.5", "--merge-radius must be a fraction of the scene's radius"},
      {"--merge-radius 0.01", "--merge-radius is vcm's (vertex merging); --method mis merges nothing"},
      {"--method vcm --adaptive", "--method vcm does not go with --adaptive"},
      {"--method vcm --aovs albedo", "--method vcm records no first surfaces, which --aovs 'albedo' asks for"},
      // What light tracing cannot do yet, named before any work.
      {"--method lt --env 1,1,1",
       "--method lt traces light paths from the emitting triangles only and does not go with --env;"},
      {"--method lt --env-map /nonexistent/sky.exr", "does not go with --env-map; use mis"},
      {"--method lt --adaptive",
       "--method lt traces light paths from the emitting triangles only and does not go with --adaptive"},
      {"--method lt --aovs albedo,spp", "--method lt records no first surfaces, which --aovs 'albedo,spp' asks for"},
      {"--method lt --denoise", "--method lt records no first surfaces, which --denoise needs"},
      {"--method bdpt --adaptive", "--method bdpt does not go with --adaptive (its passes cover chosen pixels"},
      {"--method bdpt --denoise", "--method bdpt records no first surfaces, which --denoise needs"},
  };
  for (const auto& [flags, message] : cases) {
    const auto r = test::runFredholm(std::string("render ") + flags + " -o " + dir + "/x.png");
    EXPECT_EQ(r.exitCode, 1) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << flags << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << flags << ": " << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.png"));
}

// The test hooks (base/test_hooks.h) are checked as flags are: a malformed value is one line
// naming the variable, not a hook silently off or an internal error.
TEST(RenderCli, MalformedTestHooksAreOneLineErrorsNamingTheVariable) {
  const std::string dir = test::tempDir("cli-hooks");
  for (const char* hook : {"FREDHOLM_KILL_AFTER_PASSES=three", "FREDHOLM_FAIL_DEVICE=1", "FREDHOLM_FAIL_DEVICE=1:x",
                           "FREDHOLM_FAIL_DEVICE=-1:2", "FREDHOLM_SLOW_RANK=1.5"}) {
    const auto r = test::runFredholm("render --width 8 --height 8 --spp 1 -o " + dir + "/x.png", hook);
    const std::string name = std::string(hook).substr(0, std::string(hook).find('='));
    EXPECT_EQ(r.exitCode, 1) << hook << ": " << r.output;
    EXPECT_NE(r.output.find("fredholm: error: " + name + "='"), std::string::npos) << hook << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << hook << ": " << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.png"));
}

TEST(RenderCli, StatsAndExrMetadata) {
  const std::string dir = test::tempDir("cli");
  const auto r = test::runFredholm("render --width 16 --height 12 --spp 3 --method nee --seed 7 -o " + dir +
                                   "/a.exr --stats " + dir + "/s.json");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto stats = test::readJson(dir + "/s.json");
  EXPECT_EQ(stats["samples"], 16 * 12 * 3);
  EXPECT_EQ(stats["nonfinite_samples"], 0);
  EXPECT_GT(stats["samples_per_second"].get<double>(), 0.0);
  EXPECT_EQ(stats["devices"].size(), 1u);
  EXPECT_EQ(stats["rr_depth"], 6);
  // On a CPU the automatic strategy is the megakernel with eight paths per work-item.
  const bool cpu = stats["devices"][0]["name"].get<std::string>().find("pthread") != std::string::npos;
  if (cpu) {
    EXPECT_EQ(stats["devices"][0]["strategy"], "megakernel8");
  }
  EXPECT_EQ(stats["method"], "nee");
  const auto kernels = cpu ? std::vector<const char*>{"plan_iteration", "megakernel", "finish_iteration"}
                           : std::vector<const char*>{"generate", "intersect", "shade", "shadow_connect", "accumulate"};
  for (const char* kernel : kernels) EXPECT_TRUE(stats["kernels"].contains(kernel)) << kernel;
  auto img = OIIO::ImageInput::open(dir + "/a.exr");
  ASSERT_TRUE(img);
  EXPECT_EQ(img->spec().get_string_attribute("fredholm:method"), "nee");
  EXPECT_EQ(img->spec().get_string_attribute("fredholm:seed"), "7");
  EXPECT_EQ(img->spec().width, 16);
  EXPECT_EQ(img->spec().height, 12);
  // vcm's radius, with it: the one setting of a method the other flags do not show.
  const auto vcm = test::runFredholm("render --width 8 --height 8 --spp 2 --method vcm --merge-radius 0.02 -o " + dir +
                                     "/v.exr --stats " + dir + "/v.json");
  ASSERT_EQ(vcm.exitCode, 0) << vcm.output;
  EXPECT_FLOAT_EQ(test::readJson(dir + "/v.json")["merge_radius"].get<float>(), 0.02f);
  auto vcmImage = OIIO::ImageInput::open(dir + "/v.exr");
  ASSERT_TRUE(vcmImage);
  EXPECT_EQ(vcmImage->spec().get_string_attribute("fredholm:merge_radius"), "2.000e-02");
  EXPECT_FALSE(stats.contains("merge_radius"));
  EXPECT_EQ(img->spec().get_string_attribute("fredholm:merge_radius"), "");
  // An existing --stats file is kept without --force.
  const auto again = test::runFredholm("render --width 8 --height 8 --spp 1 -o " + dir + "/b.exr --stats " + dir +
                                       "/s.json");
  EXPECT_EQ(again.exitCode, 1);
  EXPECT_NE(again.output.find("--stats '" + dir + "/s.json': file exists"), std::string::npos) << again.output;
}

TEST(RenderCli, TimeBudgetEndsOnWholePasses) {
  const std::string dir = test::tempDir("cli");
  const auto r = test::runFredholm("render --width 32 --height 32 --time 1 -o " + dir + "/t.exr --stats " + dir +
                                   "/s.json");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto stats = test::readJson(dir + "/s.json");
  const uint64_t samples = stats["samples"];
  EXPECT_GT(samples, 0u);
  EXPECT_EQ(samples % (32 * 32), 0u);           // every pixel has the same sample count
  EXPECT_LT(stats["seconds"].get<double>(), 10.0);  // the budget, plus the pass running then
}

// Ctrl-C or kill during a long render, on one device and on two: the passes finished so
// far are written, the image says it is incomplete and how many samples it holds, and the
// exit code is 128 + the signal, as for a process the signal killed.
TEST(RenderCli, ASignalWritesThePassesFinishedSoFar) {
  const std::string dir = test::tempDir("signal");
  const std::string env = "POCL_DEVICES='pthread basic'";
  for (const std::string devices : {"0", "all"}) {
    // A warm-up builds the kernels, so the signal lands while passes are being rendered.
    const std::string size = " --width 32 --height 32 --device " + devices;
    ASSERT_EQ(test::runFredholm("render" + size + " --spp 1 --force -o " + dir + "/warm.png", env).exitCode, 0);
    for (const auto& [signal, code] : {std::pair<std::string, int>{"INT", 130}, {"TERM", 143}}) {
      const std::string out = dir + "/" + signal + devices + ".exr";
      // --foreground: the signal goes to fredholm alone, once (by default timeout also signals
      // its process group, and a second SIGINT rightly exits at once without writing).
      const auto r = test::runCommand(env + " timeout --foreground --preserve-status -s " + signal + " 3 " +
                                      FREDHOLM_BINARY +
                                      " render" + size + " --spp 1000000 -o " + out);
      EXPECT_EQ(r.exitCode, code) << signal << " " << devices << ": " << r.output;
      EXPECT_NE(r.output.find("fredholm: interrupted: wrote the "), std::string::npos) << r.output;
      auto image = OIIO::ImageInput::open(out);
      ASSERT_TRUE(image) << out << " was not written: " << r.output;
      EXPECT_NE(image->spec().get_string_attribute("fredholm:incomplete").find("interrupted"), std::string::npos);
      const double spp = std::stod(image->spec().get_string_attribute("fredholm:spp", "0"));
      EXPECT_GE(spp, 1.0) << signal << " " << devices;
      EXPECT_LT(spp, 1000000.0);
      std::vector<float> pixels(32 * 32 * 3);
      ASSERT_TRUE(image->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
      double mean = 0;
      for (float v : pixels) mean += v / double(pixels.size());
      EXPECT_GT(mean, 0.01) << "the Cornell box is not black";
    }
  }
}

// A disk that fills mid-write, simulated by a file-size limit (with SIGXFSZ ignored a write
// past it fails as on a full disk): a one-line error naming the file, exit 1, the file
// that was there untouched and no temporary file left.
TEST(RenderCli, AFullDiskLeavesTheOldFileAndNoPartOfTheNew) {
  const std::string dir = test::tempDir("full");
  auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  auto limited = [](const std::string& kib, const std::string& args) {
    return test::runCommand("bash -c 'ulimit -f " + kib + "; trap \"\" XFSZ; exec " + FREDHOLM_BINARY + " " +
                            args + "'");
  };
  const std::string size = "render --width 128 --height 128 --spp 2 --force";
  for (const std::string ext : {".png", ".exr"}) {
    const std::string image = dir + "/image" + ext;
    // Also builds the kernels, so the limited run has nothing to write but its outputs.
    ASSERT_EQ(test::runFredholm(size + " -o " + image).exitCode, 0);
    const std::string before = bytes(image);
    const auto r = limited("4", size + " --seed 2 -o " + image);
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("fredholm: error: image '" + image + "': cannot write"), std::string::npos) << r.output;
    EXPECT_EQ(bytes(image), before) << ext << " was changed";
  }
  const std::string stats = dir + "/s.json";
  test::writeFile(stats, "{}\n");
  const auto r = limited("1", "render --width 8 --height 8 --spp 1 --force -o " + dir + "/small.pfm --stats " + stats);
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("fredholm: error: --stats '" + stats + "': cannot write"), std::string::npos) << r.output;
  EXPECT_EQ(bytes(stats), "{}\n");
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find("fredholm-tmp"), std::string::npos) << entry.path();
}

// A wavefront larger than the passes in flight can fill is cut to what they can.
TEST(RenderCli, WavefrontIsCappedAtWhatTheImageCanUse) {
  const std::string dir = test::tempDir("cli");
  const auto r = test::runFredholm("render --width 16 --height 16 --spp 4 --wavefront 100000000 -o " + dir +
                                   "/w.pfm --stats " + dir + "/s.json");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto stats = test::readJson(dir + "/s.json");
  EXPECT_LE(stats["wavefront"].get<size_t>(), 8u * 16u * 16u);
  EXPECT_EQ(stats["samples"], 16 * 16 * 4);
}

// A texture that cannot be decoded is named in a warning with its material.
TEST(RenderCli, AnUnreadableTextureIsAWarningNamingItAndItsMaterial) {
  const std::string dir = test::tempDir("cli");
  test::writeFile(dir + "/t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                  "usemtl painted\nf 1/1 2/2 3/3\n");
  test::writeFile(dir + "/t.mtl", "newmtl painted\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd broken.png\n");
  test::writeFile(dir + "/broken.png", "not an image\n");
  const auto r = test::runFredholm("render " + dir + "/t.obj --width 8 --height 8 --spp 1 --eye 0.3,0.3,2 "
                                   "--target 0.3,0.3,0 -o " + dir + "/t.pfm");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("fredholm: warning: material 'painted': "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("broken.png"), std::string::npos) << r.output;
}

// A float texture holds any number; a reflectance cannot: NaN, infinite, negative or above
// one texels are mended (grey, zero, scaled down as Kd is) with a warning naming them, and
// the render stays finite with an albedo of at most one.
TEST(RenderCli, TexelsNoReflectanceCanBeAreMendedWithAWarning) {
  const std::string dir = test::tempDir("cli");
  const float texels[4][3] = {{NAN, 0.f, 0.f}, {-1.f, 0.5f, 0.5f}, {4.f, 2.f, 1e30f}, {0.3f, 0.3f, 0.3f}};
  {
    auto out = OIIO::ImageOutput::create(dir + "/odd.exr");
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(dir + "/odd.exr", OIIO::ImageSpec(2, 2, 3, OIIO::TypeDesc::FLOAT)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, texels));
    out->close();
  }
  test::writeFile(dir + "/t.obj", "mtllib t.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -0.3 1.5 -0.3\n"
                                  "v 0.3 1.5 -0.3\nv 0.3 1.5 0.3\nv -0.3 1.5 0.3\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                  "usemtl painted\nf 4/4 3/3 2/2 1/1\nusemtl light\nf 5 6 7 8\n");
  test::writeFile(dir + "/t.mtl", "newmtl painted\nKd 1 1 1\nmap_Kd odd.exr\nnewmtl light\nKe 5 5 5\n");
  const auto r = test::runFredholm("render " + dir + "/t.obj --width 12 --height 12 --spp 4 --eye 0,1,3 --target "
                                   "0,0,0 --aovs albedo -o " + dir + "/t.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("fredholm: warning: material 'painted': texture '"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 not finite (made grey), 1 negative (made zero), 1 above one (scaled down to one, "
                          "hue kept)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("NaN or infinite"), std::string::npos) << r.output;
  std::vector<std::string> names;
  const std::vector<float> channels = test::exrChannels(dir + "/t.exr", &names);
  float albedo = 0.f, radiance = 0.f;
  for (size_t i = 0; i < channels.size(); ++i) {
    ASSERT_TRUE(std::isfinite(channels[i])) << names[i % names.size()];
    if (names[i % names.size()].rfind("albedo.", 0) == 0) albedo = std::max(albedo, channels[i]);
    else radiance = std::max(radiance, channels[i]);
  }
  EXPECT_GT(albedo, 0.f);
  EXPECT_LE(albedo, 1.f);
  EXPECT_GT(radiance, 0.f);
}

// A bench scene that cannot be read is refused before anything is measured: one line that
// names it and what it needs, no rows, no --json file.
TEST(BenchCli, AnUnreadableSceneIsOneLineBeforeAnyMeasurement) {
  const std::string dir = test::tempDir("cli");
  const std::pair<const char*, std::string> cases[] = {
      {"cornell sponza", "bench scene 'sponza' needs " + dir + "/none/sponza/sponza.obj (set FREDHOLM_SCENES)"},
      {"cornell bunnies-1m", "bench scene 'bunnies-1m' needs " + dir + "/none/bunny/CornellBox-Bunny.obj"},
      {"cornell spheres:0", "bench scene 'spheres:0': spheres:N takes a triangle count from 1 to 1e8"},
      {"cornell spnoza", "bench scene 'spnoza': no such scene (use cornell, bunny-box, sponza"},
  };
  for (const auto& [scenes, message] : cases) {
    const auto r = test::runFredholm(std::string("bench ") + scenes + " --width 8 --height 8 --repeats 1 --json " +
                                         dir + "/b.json",
                                     "FREDHOLM_SCENES=" + dir + "/none");
    EXPECT_EQ(r.exitCode, 1) << scenes << ": " << r.output;
    EXPECT_NE(r.output.find("fredholm: error: " + message), std::string::npos) << scenes << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << scenes << ": " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/b.json")) << scenes;
  }
  // Without FREDHOLM_SCENES the larger scenes are nowhere: the build points at no folder.
  const auto r = test::runFredholm("bench cornell sponza --width 8 --height 8 --repeats 1", "FREDHOLM_SCENES=");
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("fredholm: error: bench scene 'sponza' needs FREDHOLM_SCENES, the folder that holds "
                          "sponza/sponza.obj"),
            std::string::npos)
      << r.output;
}

TEST(RenderCli, ProgressLinesWhenNotATerminal) {
  const std::string dir = test::tempDir("cli");
  const auto r = test::runFredholm("render --width 16 --height 16 --spp 8 -o " + dir + "/p.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("fredholm: 100%"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Msamples/s"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find('\r'), std::string::npos);  // no redrawn bar in a log
}

TEST(ReferenceCli, ExactImageOfTheClosedFormSceneAndItsErrors) {
  const std::string dir = test::tempDir("cli");
  const auto ok = test::runFredholm("reference builtin:plane-under-light --width 8 --height 6 -o " + dir + "/e.exr");
  ASSERT_EQ(ok.exitCode, 0) << ok.output;
  const Image exact = readImage(dir + "/e.exr");
  EXPECT_EQ(exact.width, 8);
  EXPECT_EQ(exact.height, 6);
  for (float v : exact.rgb) EXPECT_TRUE(std::isfinite(v) && v >= 0.f);
  const auto again = test::runFredholm("reference builtin:plane-under-light -o " + dir + "/e.exr");
  EXPECT_EQ(again.exitCode, 1);
  EXPECT_NE(again.output.find("file exists"), std::string::npos) << again.output;
  const auto unknown = test::runFredholm("reference builtin:nothing -o " + dir + "/n.exr");
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.output.find("'builtin:nothing': unknown built-in scene"), std::string::npos) << unknown.output;
  const auto rendered = test::runFredholm("render builtin:plane-under-light --width 8 --height 6 --spp 4 -o " + dir +
                                          "/r.exr");
  EXPECT_EQ(rendered.exitCode, 0) << rendered.output;
}


TEST(ExportCli, BuiltinAndObjScenesRoundTripToTheSameImage) {
  const std::string dir = test::tempDir("cli");
  for (const std::string scene : {"builtin:plane-under-light", ""}) {
    const std::string obj = dir + "/exported" + (scene.empty() ? "-cornell" : "-plane") + ".obj";
    const auto exported = test::runFredholm("export " + scene + " -o " + obj);
    ASSERT_EQ(exported.exitCode, 0) << exported.output;
    EXPECT_NE(exported.output.find(".camera.json"), std::string::npos) << exported.output;
    // The same scene, camera and seed from the original and from the written files.
    const std::string flags = " --width 12 --height 10 --spp 8 --seed 3 --force -o ";
    const auto a = test::runFredholm("render " + scene + flags + dir + "/a.exr");
    const auto b = test::runFredholm("render " + obj + flags + dir + "/b.exr");
    ASSERT_EQ(a.exitCode, 0) << a.output;
    ASSERT_EQ(b.exitCode, 0) << b.output;
    EXPECT_EQ(readImage(dir + "/a.exr").rgb, readImage(dir + "/b.exr").rgb) << scene;
    const auto again = test::runFredholm("export " + scene + " -o " + obj);
    EXPECT_EQ(again.exitCode, 1);
    EXPECT_NE(again.output.find("file exists"), std::string::npos) << again.output;
  }
  const auto notObj = test::runFredholm("export -o " + dir + "/x.ply");
  EXPECT_EQ(notObj.exitCode, 1);
  EXPECT_NE(notObj.output.find("must end in .obj"), std::string::npos) << notObj.output;
}

// Single precision holds a length's square and fourth power (densities, bdpt's weights) only
// near unit size; the loader brings any scene there by a power of two, which is exact. So a
// scene in any units renders the same bits, and its depth layer is in the file's units.
TEST(RenderCli, ASceneInAnyUnitsRendersTheSameBits) {
  const std::string dir = test::tempDir("units");
  const std::string obj = test::writeFeatureScene(dir);
  const std::string flags = " --width 12 --height 10 --spp 4 --seed 5 --force ";
  for (const char* method : {"mis", "vcm"}) {
    const std::string aovs = std::string(method) == "mis" ? " --aovs depth" : "";
    const auto base =
        test::runFredholm("render " + obj + " --method " + method + aovs + flags + "-o " + dir + "/1.exr");
    ASSERT_EQ(base.exitCode, 0) << base.output;
    std::vector<std::string> names;
    const std::vector<float> expected = test::exrChannels(dir + "/1.exr", &names);
    // Far below the band, just below it, and far above it (the loader's test covers more).
    for (int exponent : {-70, -12, 110}) {
      const std::string scaled = test::writeScaledCopy(obj, exponent);
      const std::string out = dir + "/" + std::to_string(exponent) + ".exr";
      const auto r = test::runFredholm("render " + scaled + " --method " + method + aovs + flags + "-o " + out);
      ASSERT_EQ(r.exitCode, 0) << r.output;
      EXPECT_EQ(r.output.find("warning"), base.output.find("warning")) << r.output;
      const std::vector<float> got = test::exrChannels(out);
      ASSERT_EQ(got.size(), expected.size());
      size_t differing = 0;
      for (size_t i = 0; i < got.size(); ++i) {
        const bool depth = names[i % names.size()] == "depth.Z";
        const bool hit = depth && expected[i] != kNoDepth;
        differing += got[i] != (hit ? std::ldexp(expected[i], exponent) : expected[i]);
      }
      EXPECT_EQ(differing, 0u) << method << " at 2^" << exponent;
    }
  }
}

// The film keeps whole quanta of a fixed size and light paths' splats are capped, both at
// unit brightness: a scene lit by emitters far from it renders in a unit of its own (a power
// of two), the same arithmetic whatever that unit, so the image of emitters 2^k as bright is
// 2^k times the image, to the bit; and like the scene of unit brightness (its quanta aside).
TEST(RenderCli, EmittersOfAnyBrightnessRenderTheSameImageScaled) {
  const std::string dir = test::tempDir("radiance");
  const std::string obj = test::writeFeatureScene(dir);  // its light: Ke 8 8 8
  std::ifstream in(dir + "/features.mtl");
  const std::string mtl((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string flags = " --width 12 --height 10 --spp 4 --seed 5 --force ";
  // The image with the light (and --env) 2^exponent as bright.
  auto render = [&](const std::string& method, int exponent, bool env) {
    auto scaled = [&](double v) {
      char text[32];
      std::snprintf(text, sizeof text, "%.9g", std::ldexp(v, exponent));
      return std::string(text);
    };
    std::string brighter = mtl;
    brighter.replace(brighter.find("Ke 8 8 8"), 8, "Ke " + scaled(8) + " " + scaled(8) + " " + scaled(8));
    test::writeFile(dir + "/features.mtl", brighter);
    const std::string envFlag = env ? " --env " + scaled(0.25) + "," + scaled(0.25) + "," + scaled(0.25) : "";
    const std::string out = dir + "/" + method + std::to_string(exponent) + ".exr";
    const auto r = test::runFredholm("render " + obj + " --method " + method + envFlag + flags + "-o " + out);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    test::writeFile(dir + "/features.mtl", mtl);
    return test::exrChannels(out);
  };
  for (const char* method : {"mis", "lt", "vcm"}) {
    const bool env = std::string(method) == "mis";  // lt takes no environment
    const std::vector<float> expected = render(method, 20, env), unit = render(method, 0, env);
    ASSERT_FALSE(expected.empty());
    ASSERT_GT(*std::max_element(unit.begin(), unit.end()), 0.f) << method;
    for (int exponent : {-60, 100}) {
      const std::vector<float> got = render(method, exponent, env);
      ASSERT_EQ(got.size(), expected.size());
      size_t differing = 0;
      for (size_t i = 0; i < got.size(); ++i) differing += got[i] != std::ldexp(expected[i], exponent - 20);
      EXPECT_EQ(differing, 0u) << method << " at 2^" << exponent;
    }
    double sum = 0.0, unitSum = 0.0;
    for (size_t i = 0; i < unit.size(); ++i) {
      sum += std::ldexp(double(expected[i]), -20);
      unitSum += unit[i];
    }
    EXPECT_NEAR(sum, unitSum, 1e-5 * unitSum) << method;
  }
}

// Every surface of the Cornell box emitting Ke: at 1e37 its pixels are bright but within
// float, at 3e38 they sum past it, which no image file can hold: an error, and no file.
TEST(RenderCli, PixelsPastTheFloatRangeAreAnErrorAndNoFile) {
  const std::string dir = test::tempDir("float-range");
  const std::string obj = test::projectScene("cornell-box/CornellBox-Original.obj");
  std::ifstream in(obj.substr(0, obj.size() - 4) + ".mtl");
  std::string mtl;
  for (std::string line; std::getline(in, line);)
    mtl += (line.find("Ke ") != std::string::npos ? std::string("Ke KE KE KE") : line) + "\n";
  std::filesystem::copy_file(obj, dir + "/box.obj");
  auto render = [&](const std::string& ke) {
    std::string text = mtl;
    for (size_t at = text.find("KE"); at != std::string::npos; at = text.find("KE", at)) text.replace(at, 2, ke);
    test::writeFile(dir + "/CornellBox-Original.mtl", text);
    return test::runFredholm("render " + dir + "/box.obj --width 16 --height 16 --spp 4 -o " + dir + "/" + ke + ".exr");
  };
  const auto within = render("1e37");
  EXPECT_EQ(within.exitCode, 0) << within.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/1e37.exr"));
  const auto past = render("3e38");
  EXPECT_NE(past.exitCode, 0) << past.output;
  EXPECT_NE(past.output.find("fredholm: error: "), std::string::npos) << past.output;
  EXPECT_NE(past.output.find("past the float range"), std::string::npos) << past.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/3e38.exr"));
}

TEST(CompareCli, MetricsMeansAndBlocks) {
  const std::string dir = test::tempDir("cli");
  Image a, b;
  a.width = b.width = 4;
  a.height = b.height = 2;
  a.rgb.assign(24, 1.f);
  b.rgb.assign(24, 1.f);
  for (int x = 0; x < 2; ++x) a.rgb[size_t(3 * x)] = 3.f;  // two red pixels of one 2x2 block: block mean 2
  writeImage(dir + "/a.exr", a, {});
  writeImage(dir + "/b.exr", b, {});
  const auto pixels = test::runFredholm("compare " + dir + "/a.exr " + dir + "/b.exr");
  ASSERT_EQ(pixels.exitCode, 0) << pixels.output;
  const auto j = nlohmann::json::parse(pixels.output);
  EXPECT_NEAR(j["mae"].get<double>(), 4.0 / 24, 1e-6);
  EXPECT_NEAR(j["mean_image"][0].get<double>(), 1.5, 1e-6);
  EXPECT_NEAR(j["mean_reference"][0].get<double>(), 1.0, 1e-6);
  const auto blocks = test::runFredholm("compare --block 2 " + dir + "/a.exr " + dir + "/b.exr");
  ASSERT_EQ(blocks.exitCode, 0) << blocks.output;
  // Blocks: red 2 vs 1 in one of 2 blocks x 3 channels: relMSE 1 / 1.01 / 6.
  EXPECT_NEAR(nlohmann::json::parse(blocks.output)["relmse"].get<double>(), 1.0 / 1.01 / 6, 1e-6);
  const auto bad = test::runFredholm("compare --block 3 " + dir + "/a.exr " + dir + "/b.exr");
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.output.find("--block: block size 3 does not divide the image (4x2)"), std::string::npos)
      << bad.output;
}

}  // namespace
}  // namespace fh
