// Every file a command writes goes through one output plan (base/output_plan.h): outputs that
// collide with each other or with an input are refused before any work, a file that appears
// at an output during the work is kept, writability is proven up front, and signals keep the
// render (SIGHUP) or leave nothing behind (a second Ctrl-C). Also: budgets that always render.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "test_support.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The hidden temporary files of writes (base/atomic_file.cpp) in `dir`.
int temporaryFiles(const std::string& dir) {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    n += entry.path().filename().string().find(".fredholm-tmp-") != std::string::npos;
  return n;
}

// Waits (at most a minute) until `dir` holds a temporary file: the render has planned its outputs.
bool waitForReservation(const std::string& dir) {
  for (int i = 0; i < 600; ++i) {
    if (temporaryFiles(dir) > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

size_t lines(const std::string& text) { return size_t(std::count(text.begin(), text.end(), '\n')); }

std::string metadataOf(const std::string& path, const std::string& key) {
  auto in = OIIO::ImageInput::open(path);
  return in ? in->spec().get_string_attribute("fredholm:" + key) : "(unreadable)";
}

const std::string kSmall = " --width 8 --height 8 --spp 2";

TEST(OutputPlan, OutputsThatCollideAreRefusedBeforeWork) {
  const std::string dir = test::tempDir("plan");
  test::writeFile(dir + "/keep.txt", "mine");
  const std::pair<std::string, std::string> cases[] = {
      {"-o " + dir + "/x.exr --film " + dir + "/x.exr", "-o '" + dir + "/x.exr': is also the file of --film"},
      {"-o " + dir + "/x.exr --stats " + dir + "/./x.exr", "is also the file of -o"},
      {"-o " + dir + "/x.png --checkpoint " + dir + "/sub/../x.png", "is also the file of --checkpoint"},
      {"-o /proc/fredholm-test.png", "-o '/proc/fredholm-test.png': cannot write there"},
      {"-o " + dir + "/keep.txt.png --stats " + dir + "/keep.txt", "--stats '" + dir + "/keep.txt': file exists"},
  };
  fs::create_directory(dir + "/sub");
  for (const auto& [flags, message] : cases) {
    const auto r = test::runFredholm("render" + kSmall + " " + flags);
    EXPECT_EQ(r.exitCode, 1) << flags << ": " << r.output;
    EXPECT_EQ(r.output.rfind("fredholm: error: ", 0), 0u) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << flags << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1u) << flags << ": " << r.output;
    EXPECT_EQ(temporaryFiles(dir), 0) << flags;
  }
  EXPECT_EQ(readAll(dir + "/keep.txt"), "mine");
  EXPECT_FALSE(fs::exists(dir + "/x.exr"));
}

// An input is never an output, even with --force: the scene, its MTL, the camera.
TEST(OutputPlan, InputsAreNeverOverwritten) {
  const std::string dir = test::tempDir("plan");
  const std::string scene = test::writeFeatureScene(dir);
  const std::string before = readAll(scene), mtl = readAll(dir + "/features.mtl");
  const std::pair<std::string, std::string> cases[] = {
      {"-o " + dir + "/out.png --stats " + scene, "--stats '" + scene + "': is the scene"},
      {"-o " + dir + "/out.png --stats " + dir + "/features.mtl", "is the mtllib"},
      {"-o " + dir + "/checker.png", "-o '" + dir + "/checker.png': is the texture"},
  };
  for (const auto& [flags, message] : cases) {
    const auto r = test::runFredholm("render " + scene + kSmall + " --force " + flags);
    EXPECT_EQ(r.exitCode, 1) << flags << ": " << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << flags << ": " << r.output;
  }
  const auto exported = test::runFredholm("export " + scene + " --force -o " + scene);
  EXPECT_EQ(exported.exitCode, 1) << exported.output;
  EXPECT_NE(exported.output.find("-o '" + scene + "': is the scene"), std::string::npos) << exported.output;
  EXPECT_EQ(readAll(scene), before);
  EXPECT_EQ(readAll(dir + "/features.mtl"), mtl);
  EXPECT_EQ(temporaryFiles(dir), 0);
}

// A file created at -o while the render runs is kept; the render goes beside it, and says so.
TEST(OutputPlan, AFileThatAppearsDuringTheRenderIsKept) {
  const std::string dir = test::tempDir("plan");
  const std::string out = dir + "/x.png";
  std::thread intruder([&] {
    if (waitForReservation(dir)) test::writeFile(out, "appeared");
  });
  const auto r = test::runFredholm("render --width 16 --height 16 --spp 100000 --time 2 -o " + out);
  intruder.join();
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("appeared during the work and was kept, so the output is in '" + dir + "/x-1.png'"),
            std::string::npos) << r.output;
  EXPECT_EQ(readAll(out), "appeared");
  EXPECT_EQ(metadataOf(dir + "/x-1.png", "method"), "mis");
  EXPECT_EQ(temporaryFiles(dir), 0);
}

// Two renders to one -o at once: one writes it, the other goes beside it and says so.
// Two renders with the default name in one directory take two names.
TEST(OutputPlan, ConcurrentRendersNeverReplaceEachOther) {
  const std::string dir = test::tempDir("plan");
  // Each renders for 3 s after its outputs are planned, so the four overlap however their
  // start-ups differ: every plan is made before any render commits.
  const std::string render = std::string(FREDHOLM_BINARY) + " render --width 16 --height 16 --spp 1000000 --time 3";
  const auto r = test::runCommand("cd " + dir + " && { (" + render + " -o same.png > a.log 2>&1; echo $? > a.rc) & (" +
                                  render + " -o same.png > b.log 2>&1; echo $? > b.rc) & (" + render +
                                  " > c.log 2>&1) & (" + render + " > d.log 2>&1) & wait; }");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const int a = std::stoi(readAll(dir + "/a.rc")), b = std::stoi(readAll(dir + "/b.rc"));
  EXPECT_EQ(a + b, 1) << readAll(dir + "/a.log") << readAll(dir + "/b.log");
  const std::string loser = readAll(dir + (a ? "/a.log" : "/b.log"));
  EXPECT_NE(loser.find("'same.png' appeared during the work and was kept, so the output is in 'same-1.png'"),
            std::string::npos) << loser;
  EXPECT_TRUE(fs::exists(dir + "/same.png") && fs::exists(dir + "/same-1.png"));
  EXPECT_TRUE(fs::exists(dir + "/fredholm.png") && fs::exists(dir + "/fredholm-1.png"));
  EXPECT_EQ(temporaryFiles(dir), 0);
}

// A dropped terminal (SIGHUP) stops the render like SIGTERM: the passes so far are written.
// A second Ctrl-C exits at once, and leaves no temporary file behind.
TEST(OutputPlan, SignalsKeepTheRenderOrLeaveNothing) {
  const std::string dir = test::tempDir("plan");
  const std::string render = std::string(FREDHOLM_BINARY) + " render --width 16 --height 16 --spp 1000000 ";
  // The signal goes once a pass is finished: the progress display has counted its samples.
  const auto afterFirstPass = [&](const std::string& name, const std::string& signals) {
    return test::runCommand("cd " + dir + " && { " + render + "-o " + name + ".exr 2> " + name +
                            ".log & p=$!; for i in $(seq 1200); do grep -q samples " + name +
                            ".log && break; sleep 0.1; done; " + signals + " wait $p; }");
  };
  auto r = afterFirstPass("hup", "kill -HUP $p;");
  EXPECT_EQ(r.exitCode, 128 + 1) << r.output;
  EXPECT_NE(metadataOf(dir + "/hup.exr", "incomplete").find("signal 1"), std::string::npos) << r.output;
  r = afterFirstPass("int", "kill -INT $p; kill -INT $p;");
  EXPECT_EQ(r.exitCode, 128 + 2) << r.output;
  EXPECT_EQ(temporaryFiles(dir), 0);
}

TEST(Budgets, EveryBudgetRendersAtLeastOnePass) {
  const std::string dir = test::tempDir("budget");
  auto r = test::runFredholm("render --width 8 --height 8 --time 1e-9 -o " + dir + "/t.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(metadataOf(dir + "/t.exr", "spp"), "0.00") << r.output;
  EXPECT_EQ(r.output.find(" on  in "), std::string::npos) << "a device named in the summary: " << r.output;
  EXPECT_NE(r.output.find("--time 1e-09 without --spp: as many samples per pixel as the time allows"),
            std::string::npos) << r.output;
  // One sample per pixel holds no estimate of its own error: none is written.
  r = test::runFredholm("render --width 8 --height 8 --spp 1 -o " + dir + "/one.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(metadataOf(dir + "/one.exr", "estimated_relmse"), "");
  EXPECT_EQ(metadataOf(dir + "/one.exr", "spp"), "1.00");
  r = test::runFredholm("render --width 8 --height 8 --spp 2 -o " + dir + "/two.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(metadataOf(dir + "/two.exr", "estimated_relmse"), "");
}

// A resumed render says where it starts, and counts only the samples it renders itself.
TEST(Budgets, AResumedRenderSaysSoAndCountsItsOwnSamples) {
  const std::string dir = test::tempDir("budget");
  auto r = test::runFredholm("render --width 16 --height 16 --spp 4 --checkpoint " + dir + "/c.film -o " + dir + "/a.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = test::runFredholm("render --width 16 --height 16 --spp 6 --resume " + dir + "/c.film -o " + dir + "/b.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("resuming from '" + dir + "/c.film': passes 0:4 rendered; rendering from pass 4"),
            std::string::npos) << r.output;
  EXPECT_NE(r.output.find("fredholm: " + std::to_string(16 * 16 * 2) + " samples in"), std::string::npos) << r.output;
  r = test::runFredholm("render --width 16 --height 16 --spp 4 --resume " + dir + "/c.film -o " + dir + "/c.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("as many as --spp 4 asks: nothing left to render"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("on no device (nothing left to render)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("fredholm: no samples rendered"), std::string::npos) << r.output;
  // Fewer than the checkpoint holds: said, and the image keeps them all.
  r = test::runFredholm("render --width 16 --height 16 --spp 3 --resume " + dir + "/c.film -o " + dir + "/d.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("passes 0:4 rendered, more than the 3 --spp asks: nothing left to render, and the image "
                          "holds all 4"), std::string::npos) << r.output;
  EXPECT_EQ(metadataOf(dir + "/d.png", "spp"), "4.00");
}

// The rate the summary gives counts from the end of the first pass, which carries the kernels'
// build: with empty kernel caches that build dwarfs a small render, and a rate counted from the
// start (the old figure, samples over the whole time) would be mostly the compiler's.
TEST(Budgets, RatesCountFromTheEndOfTheFirstPass) {
  const std::string dir = test::tempDir("budget");
  const auto r = test::runFredholm("render --width 32 --height 32 --spp 16 -o " + dir + "/r.png --stats " + dir + "/r.json",
                                   "POCL_CACHE_DIR=" + dir + "/pocl FREDHOLM_CACHE_DIR=" + dir + "/programs");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  double total = 0, rate = 0, first = 0;
  const size_t at = r.output.find("fredholm: 16384 samples in ");
  ASSERT_NE(at, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at,
                        "fredholm: 16384 samples in %lfs: %lf Msamples/s after the first pass (the first, with any "
                        "kernel builds, took %lfs)", &total, &rate, &first), 3) << r.output;
  EXPECT_LE(first, total);
  EXPECT_GT(rate, 16384 / total * 1e-6) << "the rate counts the kernels' build: " << r.output;
  // --stats gives the same figures (the line rounds them).
  const auto stats = test::readJson(dir + "/r.json");
  const double steadyRate = stats["steady_samples_per_second"].get<double>();
  const double firstSeconds = stats["first_pass_seconds"].get<double>();
  const double seconds = stats["seconds"].get<double>();
  EXPECT_NEAR(steadyRate * 1e-6, rate, 0.006);
  EXPECT_NEAR(firstSeconds, first, 0.006);
  // 15 passes of 1024 samples after the first, in at most the time after it. Unrounded figures:
  // the passes after a slow first one can take under the line's 10 ms.
  EXPECT_LE(firstSeconds, seconds);
  EXPECT_GE(steadyRate * (seconds - firstSeconds), 15 * 1024 * 0.999) << stats.dump();
}

// CLI11's own words never reach the user: each parse error names the flag and what it takes.
TEST(CliWords, ParseErrorsNameTheFlagAndWhatItTakes) {
  const std::pair<const char*, const char*> cases[] = {
      {"render --seed 4294967296", "--seed '4294967296': expected a whole number from 0 to 4294967295"},
      {"render --seed -1", "--seed '-1': expected a whole number from 0 to 4294967295"},
      {"render --spp abc", "--spp 'abc': expected a whole number from -2147483648 to 2147483647"},
      {"render --time soon", "--time 'soon': expected a number"},
      {"render --width 1 --width 2 --width 3", "--width is given 3 times; give it once"},
      {"render --width", "--width needs a value"},
      {"render --bogus", "unknown flag '--bogus'"},
      {"render a.obj b.obj", "unexpected argument 'b.obj'"},
      {"foo", "unknown command 'foo' (use devices, render, bench, compare, reference, export, merge)"},
      {"", "give a command: devices, render"},
      {"merge", "missing parts"},
      {"render --checkpoint-every 5", "--checkpoint-every sets how often --checkpoint saves"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = test::runFredholm(args);
    EXPECT_EQ(r.exitCode, 1) << args << ": " << r.output;
    EXPECT_NE(r.output.find(std::string("fredholm: error: ") + message), std::string::npos) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1u) << args << ": " << r.output;
  }
}

}  // namespace
}  // namespace fh
