// Checkpoints (--checkpoint, --resume): a render killed with SIGKILL after any number of
// passes and resumed gives the image an uninterrupted render gives, to the bit; Ctrl-C
// leaves a checkpoint too; a checkpoint is refused by a render of other settings and when
// it is damaged, with a one-line error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "image/image_io.h"
#include "test_support.h"

namespace fh {
namespace {

const std::string kBase = "render --height 24 --spp 24";
const std::string kRender = kBase + " --width 24 --seed 3";

TEST(Checkpoint, KilledAndResumedIsTheUninterruptedImage) {
  const std::string dir = test::tempDir("checkpoint");
  ASSERT_EQ(test::runFredholm(kRender + " -o " + dir + "/straight.exr").exitCode, 0);
  const Image straight = readImage(dir + "/straight.exr");
  for (const char* passes : {"1", "7", "23"}) {
    const std::string ckpt = dir + "/c" + passes + ".fhc", out = dir + "/r" + passes + ".exr";
    // SIGKILL itself once `passes` are in a checkpoint: no image, no clean-up, as a crash.
    const auto killed = test::runFredholm(kRender + " --checkpoint " + ckpt + " --checkpoint-every 0 -o " + out,
                                          std::string("FREDHOLM_KILL_AFTER_PASSES=") + passes);
    EXPECT_NE(killed.exitCode, 0) << passes;
    EXPECT_FALSE(std::filesystem::exists(out)) << passes;
    ASSERT_TRUE(std::filesystem::exists(ckpt)) << passes << ": " << killed.output;
    const auto resumed = test::runFredholm(kRender + " --resume " + ckpt + " --checkpoint " + ckpt + " -o " + out);
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_TRUE(readImage(out).rgb == straight.rgb) << "resumed after " << passes << " passes";
  }
}

// A resumed render may go further than the first one meant to: 12 spp, then resumed to 24.
TEST(Checkpoint, ARenderCanBeExtended) {
  const std::string dir = test::tempDir("extend");
  ASSERT_EQ(test::runFredholm(kRender + " -o " + dir + "/straight.exr").exitCode, 0);
  const std::string short12 = "render --width 24 --height 24 --spp 12 --seed 3";
  ASSERT_EQ(test::runFredholm(short12 + " --checkpoint " + dir + "/c.fhc -o " + dir + "/12.exr").exitCode, 0);
  const auto r = test::runFredholm(kRender + " --resume " + dir + "/c.fhc -o " + dir + "/24.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(readImage(dir + "/24.exr").rgb == readImage(dir + "/straight.exr").rgb);
}

// A render stopped by its noise target, resumed: nothing more to do, the same image.
TEST(Checkpoint, ARenderThatMetItsNoiseTargetStaysAsItWas) {
  const std::string dir = test::tempDir("noise-resume");
  const std::string render = "render --width 24 --height 24 --noise 3e-3 --seed 3";
  ASSERT_EQ(test::runFredholm(render + " --checkpoint " + dir + "/c.fhc -o " + dir + "/a.exr").exitCode, 0);
  const auto r = test::runFredholm(render + " --resume " + dir + "/c.fhc -o " + dir + "/b.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(readImage(dir + "/a.exr").rgb == readImage(dir + "/b.exr").rgb);
}

TEST(Checkpoint, OtherSettingsOrADamagedFileAreRefused) {
  const std::string dir = test::tempDir("refuse");
  const std::string ckpt = dir + "/c.fhc";
  ASSERT_EQ(test::runFredholm(kRender + " --checkpoint " + ckpt + " -o " + dir + "/a.exr").exitCode, 0);
  for (const std::string& other : {kBase + " --width 24 --seed 4", kBase + " --width 32 --seed 3",
                                   kRender + " --method pt", kRender + " --max-depth 5", kRender + " --fov 20"}) {
    const auto r = test::runFredholm(other + " --resume " + ckpt + " -o " + dir + "/b.exr");
    EXPECT_EQ(r.exitCode, 1) << other;
    EXPECT_NE(r.output.find("fredholm: error: --resume '" + ckpt + "': saved by a render of another"),
              std::string::npos) << other << ": " << r.output;
  }
  // Cut short.
  const auto size = std::filesystem::file_size(ckpt);
  std::filesystem::resize_file(ckpt, size - 100);
  const auto cut = test::runFredholm(kRender + " --resume " + ckpt + " -o " + dir + "/c.exr");
  EXPECT_EQ(cut.exitCode, 1);
  EXPECT_NE(cut.output.find("cut short"), std::string::npos) << cut.output;
  // A header claiming a huge film over a small file: refused before allocating it.
  std::string header;
  std::getline(std::ifstream(ckpt), header);
  const std::string fingerprint = header.substr(header.find(' ') + 1, 16);
  test::writeFile(dir + "/huge.fhc", "fredholm-checkpoint-1 " + fingerprint + " 16384 16384 3 0 0\n0123");
  const auto huge = test::runFredholm(kRender + " --resume " + dir + "/huge.fhc -o " + dir + "/e.exr");
  EXPECT_EQ(huge.exitCode, 1);
  test::writeFile(dir + "/junk.fhc", "not a checkpoint\n");
  const auto junk = test::runFredholm(kRender + " --resume " + dir + "/junk.fhc -o " + dir + "/d.exr");
  EXPECT_EQ(junk.exitCode, 1);
  EXPECT_NE(junk.output.find("not a fredholm checkpoint"), std::string::npos) << junk.output;
  for (const char* f : {"/b.exr", "/c.exr", "/d.exr"}) EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;
}

// Ctrl-C: the image so far and the checkpoint are written, and resuming finishes the image
// an uninterrupted render gives.
TEST(Checkpoint, CtrlCLeavesACheckpointToResumeFrom) {
  const std::string dir = test::tempDir("ctrl-c");
  const std::string size = "render --width 32 --height 32 --seed 5", render = size + " --spp 8192";
  ASSERT_EQ(test::runFredholm(size + " --spp 1 -o " + dir + "/warm.exr").exitCode, 0);  // builds the kernels
  const auto stopped = test::runCommand(std::string("timeout --foreground --preserve-status -s INT 1 ") +
                                        FREDHOLM_BINARY + " " + render + " --checkpoint " + dir +
                                        "/c.fhc -o " + dir + "/part.exr");
  ASSERT_EQ(stopped.exitCode, 130) << stopped.output;
  EXPECT_NE(stopped.output.find("and a checkpoint to " + dir + "/c.fhc"), std::string::npos) << stopped.output;
  const auto resumed = test::runFredholm(render + " --resume " + dir + "/c.fhc -o " + dir + "/resumed.exr");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  ASSERT_EQ(test::runFredholm(render + " -o " + dir + "/straight.exr").exitCode, 0);
  EXPECT_TRUE(readImage(dir + "/resumed.exr").rgb == readImage(dir + "/straight.exr").rgb);
}

}  // namespace
}  // namespace fh
