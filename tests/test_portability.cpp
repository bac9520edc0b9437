// Portability gates: every program variant (methods x material features, intersect, bench,
// AOV) compiles strictly as OpenCL C 1.2 with no optional extensions for SPIR, NVIDIA
// (nvptx) and AMD (amdgcn) targets with Debian's clang; none leaves a helper undefined when
// nothing forces inlining; and with optimisation off every program still renders the same
// estimator on PoCL.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
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
};

const Target kTargets[] = {
    {"spir64", "-target spir64", "-emit-llvm -c"},
    {"nvptx64", "-target nvptx64-nvidia-nvcl", "-S"},
    {"amdgcn", "-target amdgcn-amd-amdhsa -mcpu=gfx900 -nogpulib", "-S"},
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

// Compiles every program variant with `flags` on all cores; returns the failures.
std::vector<Compiled> compileEveryVariant(const std::string& tag, const std::string& flags,
                                          const std::string& output) {
  const std::vector<ProgramSpec> programs = everyProgramVariant();
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
  const auto results = compileEveryVariant(target.name, std::string(kStrict) + " " + kWarnings + " -O2 " + target.flags,
                                           target.output);
  EXPECT_GE(results.size(), 51u);  // intersect, bench rays, aov, 3 methods x 16 feature sets
  for (const auto& r : results)
    EXPECT_TRUE(r.result.exitCode == 0 && r.result.output.empty())
        << target.name << ": " << r.program << " (exit " << r.result.exitCode << "):\n" << r.result.output;
}

INSTANTIATE_TEST_SUITE_P(Targets, OfflineCompile, ::testing::ValuesIn(kTargets),
                         [](const ::testing::TestParamInfo<Target>& p) { return std::string(p.param.name); });

// With inlining left to the compiler and optimisation off, every helper must have a
// definition of its own. OpenCL C follows C99, where a non-static `inline` function
// provides none: the IR then declares it, and a device that does not inline fails to link.
// OpenCL builtins are overloaded (mangled _Z...) and LLVM intrinsics start with llvm.,
// so an unmangled declaration is one of fredholm's helpers left undefined.
TEST(OfflineCompileWithoutInlining, NoHelperIsLeftUndefined) {
  ASSERT_TRUE(fs::exists(FREDHOLM_CLANG)) << "clang not found (" << FREDHOLM_CLANG << "): apt-get install clang";
  const auto results = compileEveryVariant(
      "noinline", std::string(kStrict) + " -O0 -DFH_NO_FORCED_INLINE -target spir64", "-emit-llvm -S");
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

INSTANTIATE_TEST_SUITE_P(Runs, UnderOclgrind, ::testing::Values("pt", "nee", "mis", "lt", "bdpt", "aov", "bench", "env", "bdpt_env",
                                                          "adaptive"),
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
