// Renders shared by the ranks of an mpirun job on this machine (host/distributed): the
// same image, to the bit, for -np 1, 2 and 3 as without mpirun; a rank slowed on purpose
// takes fewer passes; what ranks cannot share yet is a one-line error that ends the job.
// Open MPI as root in a container needs the OMPI_ALLOW_* variables and no single-copy
// mechanism; one PoCL thread per rank keeps the ranks from oversubscribing two cores.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "image/image_io.h"
#include "render/checkpoint.h"
#include "test_support.h"

namespace fh {
namespace {

const std::string kMpiEnvironment =
    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
    "POCL_MAX_PTHREAD_COUNT=1";

// `fredholm ARGS` on `ranks` ranks, killed if it hangs.
test::CommandResult mpirun(int ranks, const std::string& args, const std::string& environment = "") {
  return test::runCommand(kMpiEnvironment + " " + environment + " timeout 300 mpirun --oversubscribe --bind-to none -np " +
                          std::to_string(ranks) + " " + FREDHOLM_BINARY + " " + args);
}

// The fingerprint the ranks' checkpoints at `base` were saved with.
std::string savedFingerprint(const std::string& base) {
  return readFilm(rankCheckpointPath(base, 0), "test").fingerprint;
}

const std::string kRender = "render --width 24 --height 16 --seed 4 --aovs albedo,depth --force ";

TEST(Mpi, EveryRankCountGivesTheImageOfOneProcess) {
  const std::string dir = test::tempDir("mpi");
  const auto alone = test::runFredholm(kRender + "--spp 24 -o " + dir + "/alone.exr");
  ASSERT_EQ(alone.exitCode, 0) << alone.output;
  std::vector<std::string> channels;
  const std::vector<float> reference = test::exrChannels(dir + "/alone.exr", &channels);
  ASSERT_GT(channels.size(), 3u) << "the layers are missing";
  for (int ranks : {1, 2, 3}) {
    const std::string out = dir + "/np" + std::to_string(ranks) + ".exr", stats = out + ".json";
    const auto r = mpirun(ranks, kRender + "--spp 24 -o " + out + " --stats " + stats);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    // Every channel: the radiance and the first-surface layers, merged alike.
    EXPECT_TRUE(test::exrChannels(out) == reference) << ranks << " ranks";
    const auto json = test::readJson(stats);
    ASSERT_EQ(json["ranks"].size(), size_t(ranks)) << json.dump();
    uint64_t passes = 0;
    for (const auto& rank : json["ranks"]) passes += rank["passes"].get<uint64_t>();
    EXPECT_EQ(passes, 24u) << json.dump();
    EXPECT_EQ(json["spp"].get<double>(), 24.0);
  }
}

// Light tracing's and bidirectional path tracing's splats (render/light_tracer.h) merge as
// exactly across ranks.
TEST(Mpi, LightTracingOnThreeRanksGivesTheImageOfOneProcess) {
  for (const std::string method : {"lt", "bdpt", "vcm"}) {
    SCOPED_TRACE(method);
    const std::string dir = test::tempDir("mpi-" + method);
    const std::string args = "render " + test::projectScene("failure/caustic.obj") + " --method " + method +
                             " --width 24 --height 16 --seed 4 --spp 12 --force -o " + dir;
    const auto alone = test::runFredholm(args + "/alone.exr");
    ASSERT_EQ(alone.exitCode, 0) << alone.output;
    const auto r = mpirun(3, args + "/np3.exr");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(test::exrChannels(dir + "/np3.exr") == test::exrChannels(dir + "/alone.exr"));
  }
}

TEST(Mpi, ASlowedRankTakesFewerPasses) {
  const std::string dir = test::tempDir("mpi-slow");
  const std::string stats = dir + "/stats.json";
  const auto r = mpirun(2, kRender + "--spp 32 -o " + dir + "/slow.exr --stats " + stats, "FREDHOLM_SLOW_RANK=1");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto json = test::readJson(stats);
  ASSERT_EQ(json["ranks"].size(), 2u);
  const uint64_t fast = json["ranks"][0]["passes"], slow = json["ranks"][1]["passes"];
  EXPECT_EQ(fast + slow, 32u);
  EXPECT_LT(slow, fast) << json.dump(2);
  EXPECT_GT(json["ranks"][1]["bytes_sent"].get<uint64_t>(), 0u);
}

// Open MPI 4.1 ends the job when a rank dies. Every rank checkpoints its own film; rank 1
// kills itself (SIGKILL) once three of its passes are saved, and the job is rerun with
// --resume on another rank count: it renders only the passes no checkpoint holds (those in
// flight were lost) and gives the image of one uninterrupted process.
TEST(Mpi, AKilledRankIsRecoveredFromTheRanksCheckpoints) {
  const std::string dir = test::tempDir("mpi-killed");
  const std::string args = "render --width 48 --height 32 --seed 6 --spp 40 --force ";
  ASSERT_EQ(test::runFredholm(args + "-o " + dir + "/alone.exr").exitCode, 0);
  const std::string ckpt = dir + "/ck", out = dir + "/out.exr";
  const std::string each = std::string(FREDHOLM_BINARY) + " " + args + "--checkpoint " + ckpt +
                           " --checkpoint-every 0 -o " + out;
  // Rank 0 is slowed so that rank 1 takes passes enough to die after three.
  const auto killed = test::runCommand(kMpiEnvironment + " FREDHOLM_SLOW_RANK=0 timeout 300 mpirun --oversubscribe "
                                       "--bind-to none -np 1 " + each + " : -np 1 env FREDHOLM_KILL_AFTER_PASSES=3 " +
                                       each);
  EXPECT_NE(killed.exitCode, 0) << killed.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  ASSERT_EQ(rankCheckpointFiles(ckpt).size(), 2u) << killed.output;
  const auto resumed = mpirun(3, args + "--resume " + ckpt + " --checkpoint " + ckpt + " -o " + out);
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  EXPECT_TRUE(readImage(out).rgb == readImage(dir + "/alone.exr").rgb);
  // The checkpoints left hold every pass once.
  const std::string fingerprint = savedFingerprint(ckpt);
  const Film all = loadRankCheckpoints(ckpt, fingerprint, "--resume");
  EXPECT_EQ(all.describePasses(), "0:40");
}

// A render of one process, stopped, goes on shared by ranks from its checkpoint.
TEST(Mpi, ARenderOfOneProcessGoesOnUnderMpirun) {
  const std::string dir = test::tempDir("mpi-from-one");
  const std::string args = "render --width 24 --height 16 --seed 8 --force ";
  ASSERT_EQ(test::runFredholm(args + "--spp 30 -o " + dir + "/alone.exr").exitCode, 0);
  ASSERT_EQ(test::runFredholm(args + "--spp 10 -o " + dir + "/part.exr --checkpoint " + dir + "/ck").exitCode, 0);
  const auto r = mpirun(2, args + "--spp 30 --resume " + dir + "/ck --checkpoint " + dir + "/ck -o " + dir + "/out.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(readImage(dir + "/out.exr").rgb == readImage(dir + "/alone.exr").rgb);
}

// Ctrl-C on mpirun (which passes SIGTERM to the ranks): every rank stops, hands its film
// over, and rank 0 writes the image of the passes finished so far, marked incomplete.
TEST(Mpi, CtrlCWritesThePassesFinishedSoFar) {
  const std::string dir = test::tempDir("mpi-ctrl-c");
  const std::string out = dir + "/out.exr";
  const auto r = test::runCommand("(" + kMpiEnvironment + " mpirun --oversubscribe --bind-to none -np 2 " +
                                  FREDHOLM_BINARY + " render --width 32 --height 32 --spp 1000000 -o " + out +
                                  " & job=$!; sleep 8; kill -INT $job; wait $job)");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("fredholm: interrupted: wrote the "), std::string::npos) << r.output;
  ASSERT_TRUE(std::filesystem::exists(out)) << r.output;
  EXPECT_EQ(readImage(out).width, 32);
}

TEST(Mpi, WhatRanksCannotShareIsAOneLineErrorThatEndsTheJob) {
  const std::string dir = test::tempDir("mpi-refused");
  for (const std::string flag : {"--noise 1e-2", "--adaptive", "--method auto"}) {
    const auto r = mpirun(2, kRender + flag + " -o " + dir + "/n.exr");
    EXPECT_NE(r.exitCode, 0);
    const std::string error =
        "fredholm: error: under mpirun, ranks share a render without " + flag.substr(0, flag.find(' '));
    EXPECT_NE(r.output.find(error), std::string::npos) << r.output;
  }
  // Every rank's only device fails: the first error ends the job, nothing waits for ever.
  const auto failed = mpirun(2, kRender + "--spp 16 -o " + dir + "/f.exr", "FREDHOLM_FAIL_DEVICE=0:0");
  EXPECT_NE(failed.exitCode, 0);
  EXPECT_EQ(failed.exitCode == 124, false) << "the job hung";
  EXPECT_NE(failed.output.find("fredholm: error: "), std::string::npos) << failed.output;
}

}  // namespace
}  // namespace fh
