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

#include "kernel_sources.h"
#include "program_catalog.h"
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
