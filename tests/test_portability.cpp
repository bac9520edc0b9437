// Portability gates: every program variant (methods x material features, intersect, bench,
// AOV) compiles strictly as OpenCL C 1.2 with no optional extensions for SPIR, NVIDIA
// (nvptx) and AMD (amdgcn) targets with Debian's clang; none leaves a helper undefined when
// nothing forces inlining; and with optimisation off every program still renders the same
// estimator on PoCL.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "device/kernel_sources.h"
#include "image/image_io.h"
#include "scene/scene_writer.h"
#include "program_catalog.h"
#include "scene_builder.h"
#include "test_support.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

struct Target {
  const char* name;
  const char* flags;  // target triple and what it needs
  const char* output; // what to emit: every target runs its backend where one exists
  FeatureSpan span;   // the material feature sets compiled
  bool cpuLanes;      // also what only a CPU builds (cpuLaneVariants)
};

// SPIR's front end checks every variant a scene can ask for. The two back ends, which take
// most of the time, compile every kernel with none and with all of the features: both sides
// of every feature switch (FeatureSwitches.NoConditionNamesTwoFeatures below).
const Target kTargets[] = {
    {"spir64", "-target spir64", "-emit-llvm -c", FeatureSpan::EveryCombination, true},
    {"nvptx64", "-target nvptx64-nvidia-nvcl", "-S", FeatureSpan::NoneAndAll, false},
    {"amdgcn", "-target amdgcn-amd-amdhsa -mcpu=gfx900 -nogpulib", "-S", FeatureSpan::NoneAndAll, false},
};

// OpenCL C 1.2 as a device compiler sees it: the standard header, no optional extension
// (not even cl_khr_fp64), and __OPENCL_VERSION__ as every OpenCL device defines it.
const char* kStrict =
    "-x cl -cl-std=CL1.2 -D__OPENCL_VERSION__=120 -Xclang -finclude-default-header -Xclang -cl-ext=-all";
// Warnings are errors, except two that point at nothing wrong: unused kernel parameters
// (every path stage takes the whole path-state parameter list of path_state.h and uses
// part of it) and unused static helpers (a variant compiles only the features it needs).
const char* kWarnings = "-Werror -Wall -Wextra -Wno-unused-parameter -Wno-unused-function";

struct Compiled {
  std::string program;
  std::string output;  // the file the compiler wrote
  test::CommandResult result;
};

// Compiles the program variants of `span` with `flags` on all cores; returns each result.
std::vector<Compiled> compileVariants(FeatureSpan span, bool cpuLanes, const std::string& tag,
                                      const std::string& flags, const std::string& output) {
  std::vector<ProgramSpec> programs = programVariants(span);
  if (cpuLanes)
    for (ProgramSpec& p : cpuLaneVariants()) programs.push_back(std::move(p));
  const std::string dir = test::tempDir(tag);
  std::vector<Compiled> results(programs.size());
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < programs.size(); i = next++) {
      const std::string source = dir + "/program" + std::to_string(i) + ".cl";
      test::writeFile(source, assembleKernelSources(programs[i].files));
      results[i].program = programs[i].name + " [" + programs[i].options + "]";
      results[i].output = source + ".out";
      results[i].result = test::runCommand(std::string(FREDHOLM_CLANG) + " " + flags + " " + programs[i].options +
                                           " " + output + " -o " + results[i].output + " " + source);
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < std::max(1u, std::thread::hardware_concurrency()); ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  return results;
}

class OfflineCompile : public ::testing::TestWithParam<Target> {};

TEST_P(OfflineCompile, EveryProgramVariantWithoutErrorsOrWarnings) {
  ASSERT_TRUE(fs::exists(FREDHOLM_CLANG)) << "clang not found (" << FREDHOLM_CLANG << "): apt-get install clang";
  const Target& target = GetParam();
  const auto results = compileVariants(target.span, target.cpuLanes, target.name,
                                       std::string(kStrict) + " " + kWarnings + " -O2 " + target.flags, target.output);
  // intersect, bench rays, aov, 3 methods x 2 strategies x the feature sets
  EXPECT_GE(results.size(), target.span == FeatureSpan::EveryCombination ? 99u : 15u);
  for (const auto& r : results)
    EXPECT_TRUE(r.result.exitCode == 0 && r.result.output.empty())
        << target.name << ": " << r.program << " (exit " << r.result.exitCode << "):\n" << r.result.output;
}

INSTANTIATE_TEST_SUITE_P(Targets, OfflineCompile, ::testing::ValuesIn(kTargets),
                         [](const ::testing::TestParamInfo<Target>& p) { return std::string(p.param.name); });

// The back ends' span holds if no kernel code depends on two features together: no
// preprocessor condition names two feature macros, and none naming a feature sits inside
// another feature's condition. Read in each program's source as the host assembles it
// (includes inlined), so a condition around an #include counts as the included code's.
TEST(FeatureSwitches, NoConditionNamesTwoFeatures) {
  const std::vector<std::string> macros = featureMacros();
  ASSERT_EQ(macros.size(), 5u);  // glossy, glass, textures, vertex normals, environment map
  const std::regex directive(R"(^\s*#\s*(if|ifdef|ifndef|elif|else|endif)\b(.*))"),
      marker(R"re(^\s*#\s*line\s+(\d+)\s+"([^"]*)")re");
  size_t featureConditions = 0;
  std::set<std::string> reported;
  for (const ProgramSpec& program : programVariants(FeatureSpan::NoneAndAll)) {
    std::istringstream source(assembleKernelSources(program.files));
    std::vector<std::set<std::string>> open;  // the feature macros each open condition names
    std::string line, file = program.name;
    std::smatch m;
    for (int number = 1; std::getline(source, line); ++number) {
      if (std::regex_search(line, m, marker)) {  // the host's markers: where the next line comes from
        number = std::stoi(m[1].str()) - 1;
        file = m[2].str();
        continue;
      }
      if (!std::regex_search(line, m, directive)) continue;
      const std::string kind = m[1].str(), condition = m[2].str();
      if (kind == "endif") {
        ASSERT_FALSE(open.empty()) << file << ":" << number << ": an #endif without its #if";
        open.pop_back();
        continue;
      }
      if (kind == "else") continue;
      std::set<std::string> named;
      for (const std::string& macro : macros)
        if (std::regex_search(condition, std::regex("\\b" + macro + "\\b"))) named.insert(macro);
      std::set<std::string> outer;
      for (size_t i = 0; i + (kind == "elif" ? 1 : 0) < open.size(); ++i) outer.insert(open[i].begin(), open[i].end());
      for (const std::string& macro : named) outer.erase(macro);
      featureConditions += !named.empty();
      const std::string where = file + ":" + std::to_string(number);
      const bool twoFeatures = named.size() >= 2 || (!named.empty() && !outer.empty());
      if (twoFeatures && reported.insert(where).second)  // once, though many programs include it
        ADD_FAILURE() << where << ": '" << line << "' makes code depend on two features; compile every combination "
            << "on every target (FeatureSpan)";
      if (kind == "elif")
        open.back().insert(named.begin(), named.end());
      else
        open.push_back(named);
    }
  }
  EXPECT_GT(featureConditions, 20u);  // the scan saw the feature switches
}

// The back ends compile each program of the front end's catalogue (its kernel files and
// options but the feature macros) with no feature and with every feature it is ever built
// with, and nothing the front end does not also compile.
TEST(FeatureSwitches, BackEndsBuildEachProgramWithNoneAndAll) {
  const std::vector<std::string> macros = featureMacros();
  // A program without its feature macros, and those macros.
  auto split = [&](const ProgramSpec& p) {
    std::string rest, token;
    std::set<std::string> features;
    for (std::istringstream in(p.options); in >> token;) {
      if (std::find(macros.begin(), macros.end(), token.substr(std::min<size_t>(2, token.size()))) != macros.end())
        features.insert(token);
      else
        rest += " " + token;
    }
    std::string key;
    for (const std::string& f : p.files) key += f + ",";
    return std::pair{key + rest, features};
  };
  std::map<std::string, std::set<std::set<std::string>>> every, ends;
  for (const ProgramSpec& p : programVariants(FeatureSpan::EveryCombination)) {
    const auto [key, features] = split(p);
    every[key].insert(features);
  }
  for (const ProgramSpec& p : programVariants(FeatureSpan::NoneAndAll)) {
    const auto [key, features] = split(p);
    EXPECT_EQ(every.count(key) && every[key].count(features), 1u)
        << p.name << " [" << p.options << "] is not among every combination's programs";
    ends[key].insert(features);
  }
  size_t programs = 0, endPrograms = 0;
  for (const auto& [key, sets] : every) {
    std::set<std::string> most;
    for (const auto& features : sets) most.insert(features.begin(), features.end());
    EXPECT_EQ(ends[key].count(*sets.begin()), 1u) << key << ": the back ends build it without its fewest features";
    EXPECT_EQ(ends[key].count(most), 1u) << key << ": the back ends build it without all of its features together";
    programs += sets.size();
    endPrograms += ends[key].size();
  }
  EXPECT_LT(endPrograms, programs / 2);
}

// With inlining left to the compiler and optimisation off, every helper must have a
// definition of its own. OpenCL C follows C99, where a non-static `inline` function
// provides none: the IR then declares it, and a device that does not inline fails to link.
// OpenCL builtins are overloaded (mangled _Z...) and LLVM intrinsics start with llvm.,
// so an unmangled declaration is one of fredholm's helpers left undefined.
TEST(OfflineCompileWithoutInlining, NoHelperIsLeftUndefined) {
  ASSERT_TRUE(fs::exists(FREDHOLM_CLANG)) << "clang not found (" << FREDHOLM_CLANG << "): apt-get install clang";
  const auto results = compileVariants(FeatureSpan::EveryCombination, true, "noinline",
                                       std::string(kStrict) + " -O0 -DFH_NO_FORCED_INLINE -target spir64",
                                       "-emit-llvm -S");
  const std::regex declaration(R"(^declare [^@]*@([A-Za-z_][A-Za-z0-9_.]*)\()");
  for (const auto& r : results) {
    ASSERT_EQ(r.result.exitCode, 0) << r.program << ":\n" << r.result.output;
    std::ifstream in(r.output);
    ASSERT_TRUE(in) << r.output;
    std::string line, undefined;
    std::smatch m;
    while (std::getline(in, line))
      if (std::regex_search(line, m, declaration) && m[1].str().rfind("_Z", 0) != 0 &&
          m[1].str().rfind("llvm.", 0) != 0)
        undefined += " " + m[1].str();
    EXPECT_TRUE(undefined.empty()) << r.program << " declares helpers it never defines:" << undefined;
  }
}

}  // namespace
}  // namespace fh

namespace fh {
namespace {

// What a device compiler that does not optimise or inline sees.
const char* kOptimisationOff = "FREDHOLM_CL_OPTIONS='-cl-opt-disable -DFH_NO_FORCED_INLINE'";

// Writes the feature scene and a scene of twelve coincident copies of a slanted quad under
// a light (duplicated faces reach the intersect kernel's tie between leaves).
struct GateScenes {
  std::string dir = test::tempDir("gate-scenes");
  std::string features = test::writeFeatureScene(dir);
  std::string copies = [this] {
    test::SceneBuilder b;
    b.quadFacing({-3, 2, -3}, {-3, 2, 3}, {3, 2, 3}, {3, 2, -3}, {0, 0, 0}, b.material(0.f, 4.f));
    test::coincidentQuads(b, 12, b.material(0.5f));
    Scene scene = b.build();
    scene.camera.eye = {0, 0, 4};
    scene.camera.target = {0, 0, 0};
    scene.camera.fovYDeg = 50.f;
    scene.hasCamera = true;
    writeObjScene(scene, dir + "/copies.obj", false);
    return dir + "/copies.obj";
  }();
};

double relMse(const std::string& image, const std::string& reference) {
  const test::CommandResult r = test::runFredholm("compare " + image + " " + reference);
  const auto json = nlohmann::json::parse(r.output, nullptr, false);
  return r.exitCode == 0 && json.contains("relmse") ? json["relmse"].get<double>() : INFINITY;
}

// With optimisation and forced inlining off, every method renders the feature scene to the
// same image as the optimised build (up to float rounding, which may steer a few paths).
TEST(OptimisationOff, EveryMethodRendersWhatTheOptimisedBuildRenders) {
  const GateScenes scenes;
  for (const char* method : {"pt", "nee", "mis"}) {
    const std::string args = "render " + scenes.features + " --method " + method +
                             " --width 16 --height 16 --spp 16 --seed 5 --wavefront 256 --force -o ";
    const std::string optimised = scenes.dir + "/" + method + "-optimised.exr";
    const std::string unoptimised = scenes.dir + "/" + method + "-unoptimised.exr";
    const std::string cache = "FREDHOLM_CACHE_DIR=" + scenes.dir + "/cache";
    const test::CommandResult a = test::runFredholm(args + optimised, cache);
    ASSERT_EQ(a.exitCode, 0) << a.output;
    const test::CommandResult b = test::runFredholm(args + unoptimised, cache + " " + kOptimisationOff);
    ASSERT_EQ(b.exitCode, 0) << b.output;
    EXPECT_NE(a.output.find("glossy, glass, textures, shading normals"), std::string::npos) << a.output;
    EXPECT_LT(relMse(unoptimised, optimised), 1e-3) << method;
  }
}

// Oclgrind simulates an OpenCL device and reports invalid memory accesses, data races and
// API misuse. Its 21.10 release needs optimisation off (it lacks llvm.bitreverse and the
// noalias-scope intrinsics that forced inlining leaves) and mis-executes the optimised
// intersect_block. Every report goes to a log that must stay empty.
class UnderOclgrind : public ::testing::TestWithParam<const char*> {};

// A small environment map of uneven texels (some black) in `dir`; returns its path.
std::string writeEnvironmentMap(const std::string& dir) {
  Image map;
  map.width = 8;
  map.height = 4;
  for (int p = 0; p < 32; ++p) map.rgb.insert(map.rgb.end(), {float(p % 5), float(p % 3), 0.5f * float(p % 2)});
  const std::string path = dir + "/sky.exr";
  writeImage(path, map, {});
  return path;
}

TEST_P(UnderOclgrind, RunsWithoutReports) {
  ASSERT_TRUE(fs::exists("/usr/bin/oclgrind")) << "oclgrind not found: apt-get install oclgrind";
  const GateScenes scenes;
  const std::string run = GetParam();
  std::string args;
  if (run == "bench")
    args = "bench " + scenes.features + " --width 8 --height 8 --repeats 1";
  else if (run == "aov")
    args = "render " + scenes.copies + " --aov normal --width 8 --height 8 -o " + scenes.dir + "/aov.exr";
  else if (run == "adaptive")  // later rounds' passes cover some pixels (render/adaptive.h)
    args = "render " + test::projectScene("failure/caustic.obj") +
           " --adaptive --width 8 --height 8 --spp 24 --wavefront 64 -o " + scenes.dir + "/adaptive.exr";
  else if (run == "env" || run == "bdpt_env")  // an environment map beside the scene's light
    args = "render " + scenes.features + " --env-map " + writeEnvironmentMap(scenes.dir) +
           (run == "env" ? "" : " --method bdpt") + " --width 8 --height 8 --spp 1 --wavefront 64 -o " + scenes.dir +
           "/" + run + ".exr";
  else if (run == "bdpt_lanes" || run == "vcm_lanes")  // eight paths a work-item, some lanes past the image
    args = "render " + scenes.features + " --method " + run.substr(0, run.find('_')) +
           " --strategy megakernel8 --width 7 --height 5 --spp 1 -o " + scenes.dir + "/" + run + ".exr";
  else
    args = "render " + scenes.features + " --method " + run + " --width 8 --height 8 --spp 1 --wavefront 64 -o " +
           scenes.dir + "/" + run + ".exr";
  const std::string log = scenes.dir + "/oclgrind.log";
  const test::CommandResult r = test::runCommand(
      std::string(kOptimisationOff) + " FREDHOLM_CACHE_DIR=" + scenes.dir + "/cache oclgrind --check-api --data-races" +
      " --log " + log + " " + FREDHOLM_BINARY + " " + args);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("Oclgrind"), std::string::npos) << "not run on Oclgrind's device:\n" << r.output;
  std::ifstream in(log);
  const std::string reports((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(reports.empty()) << run << ": Oclgrind reported:\n" << reports.substr(0, 4000);
}

INSTANTIATE_TEST_SUITE_P(Runs, UnderOclgrind,
                         ::testing::Values("pt", "nee", "mis", "lt", "bdpt", "bdpt_lanes", "vcm", "vcm_lanes", "aov",
                                           "bench", "env", "bdpt_env", "adaptive"),
                         [](const ::testing::TestParamInfo<const char*>& p) { return std::string(p.param); });

}  // namespace
}  // namespace fh

namespace fh {
namespace {

// The GPU measurement script runs end to end here too, on PoCL with small sizes, so a first
// GPU attempt can fail only on what is truly GPU-specific. Its CPU comparison then compares
// two renders of the same CPU device: their relMSE must match that of two seeds.
TEST(GpuScript, RunsEndToEndOnPoclWithSmallSizes) {
  const std::string out = test::tempDir("gpu-script");
  const test::CommandResult r = test::runCommand(std::string(FREDHOLM_SOURCE_DIR) + "/bench/gpu/run_gpu.sh --small " +
                                                 FREDHOLM_BINARY + " " + out);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto results = test::readJson(out + "/results.json");
  EXPECT_GT(results["cornell_mis"]["msamples_per_s"].get<double>(), 0.0) << results;
  EXPECT_GT(results["best_wavefront"].get<double>(), 0.0) << results;
  const double ratio = results["cornell_mis"]["cpu"]["relmse_ratio_to_two_gpu_seeds"].get<double>();
  EXPECT_GT(ratio, 0.5) << results;
  EXPECT_LT(ratio, 2.0) << results;
  EXPECT_TRUE(results["missing"].empty()) << results;
}

}  // namespace
}  // namespace fh
