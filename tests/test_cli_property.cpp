// The command line as a hostile user meets it: random combinations of flags and values, good
// and bad, for render, merge, compare and bench. Whatever they are, fredholm exits 0 or 1;
// on 1 it says why in exactly one `fredholm: error:` line, and leaves no file behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <set>
#include <sstream>

#include "test_support.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

struct Flag {
  std::string name;  // "" for a positional argument
  std::vector<std::string> values;  // "" for a flag that takes none
};

// Every file in `dir`, hidden ones too.
std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) files.insert(entry.path().string());
  return files;
}

std::vector<std::string> errorLines(const std::string& output) {
  std::vector<std::string> found;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);)
    if (line.find("error:") != std::string::npos) found.push_back(line);
  return found;
}

class CliProperty : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir("cli-property");
    fs::create_directory(dir_ + "/sub");
    test::writeFile(dir_ + "/garbage.obj", "v 1 2\nf 1 2 9\n\x01\x02");
    test::writeFile(dir_ + "/garbage.json", "{\"eye\": [0, 1");
    test::writeFile(dir_ + "/garbage.film", "fredholm-film-9 x 1 1\n");
    test::writeFile(dir_ + "/garbage.exr", "not an image");
    test::writeFile(dir_ + "/scene.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    // A real film and image to merge and compare.
    ASSERT_EQ(test::runFredholm("render --width 8 --height 8 --passes 0:2 --film " + dir_ + "/good.film -o " + dir_ +
                                "/good.exr").exitCode, 0);
  }

  // Runs `command` with a random pick of `flags` (each present with probability 1/2, the
  // value picked uniformly) and checks the property; returns the command line.
  void tryOnce(const std::string& command, const std::vector<Flag>& flags) {
    std::string args = command;
    for (const Flag& flag : flags) {
      if (rng_() % 2) continue;
      const std::string& value = flag.values[rng_() % flag.values.size()];
      args += " " + flag.name + (value.empty() ? "" : (flag.name.empty() ? "" : " ") + value);
    }
    const std::set<std::string> before = filesIn(dir_);
    const auto r = test::runCommand("cd " + dir_ + " && timeout 120 " + FREDHOLM_BINARY + " " + args);
    ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 1) << args << " exited " << r.exitCode << ":\n" << r.output;
    const std::vector<std::string> errors = errorLines(r.output);
    if (r.exitCode == 1) {
      ASSERT_EQ(errors.size(), 1u) << args << ":\n" << r.output;
      EXPECT_EQ(errors[0].rfind("fredholm: error: ", 0), 0u) << args << ":\n" << r.output;
      EXPECT_EQ(filesIn(dir_), before) << args << ": a failed command left files behind";
    } else {
      EXPECT_TRUE(errors.empty()) << args << ":\n" << r.output;
    }
    for (const std::string& file : filesIn(dir_))
      EXPECT_EQ(file.find(".fredholm-tmp-"), std::string::npos) << args << " left " << file;
    ++runs_;
  }

  std::string dir_;
  std::mt19937 rng_{20261204};
  int runs_ = 0;
};

const std::vector<std::string> kCounts = {"1", "2", "0", "-3", "abc", "1e3", "99999999999"};

TEST_F(CliProperty, RenderExitsZeroOrOneWithOneErrorLine) {
  const std::vector<Flag> flags = {
      {"", {"scene.obj", "garbage.obj", "/dev/zero", "sub", "builtin:plane-under-light", "missing.obj"}},
      {"--width", {"8", "0", "-4", "x", "99999999"}},
      {"--height", {"8", "6", "0", "1e2"}},
      {"--spp", kCounts},
      {"--time", {"0.2", "1e-9", "-1", "nan", "soon"}},
      {"--method", {"pt", "nee", "mis", "bdpt"}},
      {"--filter", {"box", "gaussian", "tent"}},
      {"--seed", {"7", "-1", "4294967296", "x"}},
      {"-o", {"a.png", "a.tga", "/proc/x.png", "nodir/a.png", "sub", "scene.obj", "a.exr"}},
      {"--film", {"f.film", "a.png", "garbage.film"}},
      {"--stats", {"s.json", "scene.obj", "a.png"}},
      {"--camera", {"/dev/zero", "garbage.json", "missing.json", "sub"}},
      {"--resume", {"/dev/zero", "garbage.film", "good.film"}},
      {"--passes", {"0:2", "2:1", "x", "4294967295:4294967296"}},
      {"--aovs", {"albedo", "albedo,albedo", "x"}},
      {"--env-map", {"/dev/zero", "garbage.exr", "good.exr"}},
      {"--checkpoint", {"c.film", "scene.obj"}},
      {"--checkpoint-every", {"5", "-1"}},
      {"--max-depth", {"0", "3"}},
      {"--device", {"0", "7", "gpu"}},
      {"--force", {""}},
  };
  for (int i = 0; i < 40 && !HasFatalFailure(); ++i) tryOnce("render", flags);
  EXPECT_EQ(runs_, 40);
}

TEST_F(CliProperty, MergeCompareAndBenchExitZeroOrOneWithOneErrorLine) {
  const std::vector<Flag> merge = {{"", {"good.film", "garbage.film", "/dev/zero", "missing.film", "sub"}},
                                   {"", {"good.film", "garbage.film"}},
                                   {"-o", {"m.png", "m.tga", "good.film", "/proc/m.png", "sub"}},
                                   {"--aovs", {"albedo", "x"}},
                                   {"--force", {""}}};
  const std::vector<Flag> compare = {{"", {"good.exr", "garbage.exr", "/dev/zero", "missing.exr"}},
                                     {"", {"good.exr", "garbage.exr", "sub"}},
                                     {"--block", {"1", "2", "0", "3", "x"}}};
  const std::vector<Flag> bench = {{"", {"cornell", "missing.obj", "spheres:x", "garbage.obj", "/dev/zero"}},
                                   {"--width", {"4", "0", "x"}},
                                   {"--height", {"4", "-1"}},
                                   {"--repeats", {"1", "0"}},
                                   {"--json", {"b.json", "scene.obj", "/proc/b.json"}},
                                   {"--device", {"0", "9"}},
                                   {"--force", {""}}};
  for (int i = 0; i < 16 && !HasFatalFailure(); ++i) tryOnce("merge", merge);
  for (int i = 0; i < 16 && !HasFatalFailure(); ++i) tryOnce("compare", compare);
  // Small batches: a bench that runs measures 4x4 rays once.
  for (int i = 0; i < 12 && !HasFatalFailure(); ++i) tryOnce("bench --width 4 --height 4 --repeats 1", bench);
  EXPECT_EQ(runs_, 44);
}

}  // namespace
}  // namespace fh
