// Program assembly (#line markers), build failures with the device's log, and the
// on-disk binary cache.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "accel/ray_caster.h"
#include "device/devices.h"
#include "device/kernel_sources.h"
#include "device/program.h"
#include "test_support.h"

namespace fh {
namespace {

TEST(Program, IncludesAreInlinedOnceWithLineMarkers) {
  const std::string src = assembleKernelSource("intersect.cl");
  EXPECT_EQ(src.rfind("#line 1 \"kernels/intersect.cl\"", 0), 0u);
  EXPECT_NE(src.find("#line 1 \"kernels/intersect.h\""), std::string::npos);
  const size_t types = src.find("#line 1 \"kernels/types.h\"");
  ASSERT_NE(types, std::string::npos);
  EXPECT_EQ(src.find("#line 1 \"kernels/types.h\"", types + 1), std::string::npos);
  // After intersect.cl's include on its line 2, its text resumes at line 3.
  EXPECT_NE(src.find("#line 3 \"kernels/intersect.cl\""), std::string::npos);
  EXPECT_THROW(assembleKernelSource("nonexistent.cl"), Error);
}

class ProgramOnDevice : public ::testing::Test {
 protected:
  void SetUp() override {
    cacheDir = test::tempDir("cache");
    setenv("FREDHOLM_CACHE_DIR", cacheDir.c_str(), 1);
  }
  DeviceContext dc{selectDevices(listDevices(), "").front()};
  std::string cacheDir;
};

TEST_F(ProgramOnDevice, BuildFailureCarriesTheLogWithRealFileAndLine) {
  const std::string source =
      "#line 1 \"kernels/broken.cl\"\n"
      "__kernel void broken(__global float* x) {\n"
      "  x[0] = undefined_symbol;\n"
      "}\n";
  try {
    buildProgramFromSource(dc.context, dc.info.device, source, "");
    FAIL() << "no error";
  } catch (const BuildError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("kernel build failed"), std::string::npos) << msg;
    EXPECT_NE(msg.find("kernels/broken.cl:2"), std::string::npos) << msg;  // #line 1 names the next line
    EXPECT_NE(msg.find("undefined_symbol"), std::string::npos) << msg;
  }
}

TEST_F(ProgramOnDevice, SecondBuildComesFromTheCache) {
  // A nonce in the options makes the first build cold even if an earlier run cached it.
  const std::string options = "-DFH_TEST_NONCE=" + std::to_string(std::random_device{}());
  ProgramBuildInfo first, second;
  buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, options, &first);
  const cl::Program program = buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, options, &second);
  EXPECT_FALSE(first.fromCache);
  EXPECT_TRUE(second.fromCache);
  EXPECT_EQ(first.cacheFile, second.cacheFile);
  EXPECT_EQ(first.cacheFile.rfind(cacheDir, 0), 0u);
  EXPECT_NO_THROW(createKernel(program, "generate_camera_rays"));
  // Other options are another program.
  ProgramBuildInfo other;
  buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, options + " -DFH_OTHER=1", &other);
  EXPECT_FALSE(other.fromCache);
}

TEST_F(ProgramOnDevice, CorruptCacheFileFallsBackToSource) {
  const std::string options = "-DFH_TEST_NONCE=" + std::to_string(std::random_device{}());
  ProgramBuildInfo first, second;
  buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, options, &first);
  test::writeFile(first.cacheFile, "not a binary");
  buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, options, &second);
  EXPECT_FALSE(second.fromCache);
}

TEST_F(ProgramOnDevice, MissingKernelNameIsAnError) {
  const cl::Program program = buildProgram(dc.context, dc.info.device, {"camera_rays.cl"}, "");
  try {
    createKernel(program, "no_such_kernel");
    FAIL();
  } catch (const ClError& e) {
    EXPECT_NE(std::string(e.what()).find("CL_INVALID_KERNEL_NAME"), std::string::npos) << e.what();
  }
}

TEST_F(ProgramOnDevice, OversizedAllocationIsReportedAsOutOfMemory) {
  const cl_ulong maxAlloc = dc.info.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  try {
    allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, size_t(maxAlloc) + 1, "test buffer");
    FAIL();
  } catch (const ClError& e) {
    EXPECT_NE(std::string(e.what()).find("device out of memory: test buffer"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fh
