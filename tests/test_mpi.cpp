// Renders shared by the ranks of an mpirun job on this machine (host/distributed): the
// same image, to the bit, for -np 1, 2 and 3 as without mpirun; a rank slowed on purpose
// takes fewer passes; what ranks cannot share yet is a one-line error that ends the job.
// Open MPI as root in a container needs the OMPI_ALLOW_* variables and no single-copy
// mechanism; one PoCL thread per rank keeps the ranks from oversubscribing two cores.
#include <gtest/gtest.h>

#include <string>

#include "image/image_io.h"
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

const std::string kRender = "render --width 24 --height 16 --seed 4 --aovs albedo,depth --force ";

TEST(Mpi, EveryRankCountGivesTheImageOfOneProcess) {
  const std::string dir = test::tempDir("mpi");
  const auto alone = test::runFredholm(kRender + "--spp 24 -o " + dir + "/alone.exr");
  ASSERT_EQ(alone.exitCode, 0) << alone.output;
  const Image reference = readImage(dir + "/alone.exr");
  for (int ranks : {1, 2, 3}) {
    const std::string out = dir + "/np" + std::to_string(ranks) + ".exr", stats = out + ".json";
    const auto r = mpirun(ranks, kRender + "--spp 24 -o " + out + " --stats " + stats);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(readImage(out).rgb == reference.rgb) << ranks << " ranks";
    const auto json = test::readJson(stats);
    ASSERT_EQ(json["ranks"].size(), size_t(ranks)) << json.dump();
    uint64_t passes = 0;
    for (const auto& rank : json["ranks"]) passes += rank["passes"].get<uint64_t>();
    EXPECT_EQ(passes, 24u) << json.dump();
    EXPECT_EQ(json["spp"].get<double>(), 24.0);
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

TEST(Mpi, WhatRanksCannotShareIsAOneLineErrorThatEndsTheJob) {
  const std::string dir = test::tempDir("mpi-refused");
  const auto r = mpirun(2, kRender + "--noise 1e-2 -o " + dir + "/n.exr");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("fredholm: error: under mpirun, ranks share a render without --noise"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace fh
