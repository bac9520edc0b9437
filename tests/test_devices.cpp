// Device listing and the --device grammar, on PoCL; the CLI's messages and exit codes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <sstream>

#include "device/devices.h"
#include "test_support.h"

namespace fh {
namespace {

TEST(Devices, ListsAtLeastOneDeviceWithItsProperties) {
  const auto all = listDevices();
  ASSERT_FALSE(all.empty());
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].index, int(i));
    EXPECT_FALSE(all[i].name.empty());
    EXPECT_GT(all[i].computeUnits, 0u);
    EXPECT_GT(all[i].globalMemory, 0u);
    EXPECT_NE(all[i].openclCVersion.find("OpenCL C"), std::string::npos);
  }
}

TEST(Devices, SpecGrammar) {
  const auto all = listDevices();
  EXPECT_EQ(selectDevices(all, "").size(), 1u);
  EXPECT_EQ(selectDevices(all, "all").size(), all.size());
  EXPECT_EQ(selectDevices(all, "0").front().index, 0);
  EXPECT_EQ(selectDevices(all, "0,0").size(), 1u);  // repeats collapse
  EXPECT_EQ(selectDevices(all, all[0].type).front().type, all[0].type);
  // A case-insensitive name substring.
  std::string part = all[0].name.substr(0, 4);
  for (char& c : part) c = char(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(selectDevices(all, part).front().index, 0);
}

TEST(Devices, SpecThatMatchesNothingSaysWhatExists) {
  const auto all = listDevices();
  try {
    selectDevices(all, std::to_string(all.size() + 6));
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("no device with index"), std::string::npos) << msg;
    EXPECT_NE(msg.find(all[0].name), std::string::npos) << msg;
  }
  EXPECT_THROW(selectDevices(all, "no-such-device-name"), Error);
  EXPECT_THROW(selectDevices(all, "0,,1"), Error);
}

TEST(DevicesCli, TwoPoclDevices) {
  const auto r = test::runFredholm("devices", "POCL_DEVICES='pthread pthread'");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("\n0 "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\n1 "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("\n2 "), std::string::npos) << r.output;
}

TEST(DevicesCli, UnknownIndexExitsNonZeroWithOneLine) {
  const auto r = test::runFredholm("render --device 7 -o /tmp/fredholm-never-written.png", "POCL_DEVICES=pthread");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("fredholm: error: --device '7': no device with index 7; available: 0 = "),
            std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(DevicesCli, NoOpenClPlatformIsAClearError) {
  // An empty vendor directory leaves the ICD loader with no platform at all.
  const std::string dir = test::tempDir("icd");
  const auto r = test::runFredholm("devices", "OCL_ICD_VENDORS=" + dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("fredholm: error: no OpenCL platform found"), std::string::npos) << r.output;
}

TEST(Devices, CpuWorkersArePinnedOnlyWhereThatKeepsThemOnTheAllowedCpus) {
  EXPECT_TRUE(cpuWorkersMayBePinned({0, 1}, 2));
  EXPECT_TRUE(cpuWorkersMayBePinned({1, 0}, 2));
  EXPECT_TRUE(cpuWorkersMayBePinned({0, 1, 2, 3}, 4));
  EXPECT_FALSE(cpuWorkersMayBePinned({0}, 2));     // taskset -c 0 on two CPUs
  EXPECT_FALSE(cpuWorkersMayBePinned({2, 3}, 4));  // a container's cpuset without CPU 0
  EXPECT_FALSE(cpuWorkersMayBePinned({0, 2}, 2));  // a gap in the numbering
  EXPECT_FALSE(cpuWorkersMayBePinned({1}, 1));
  EXPECT_FALSE(cpuWorkersMayBePinned({}, 0));
}

// Each thread's allowed CPUs (Cpus_allowed_list), a line per thread, of a render started with
// `prefix` in front of it, once PoCL's workers are up (a second thread, then a second more);
// the render is then stopped.
std::vector<std::string> renderThreadCpus(const std::string& prefix) {
  const std::string dir = test::tempDir("affinity");
  test::writeFile(dir + "/run.sh",
                  prefix + " env POCL_DEVICES=pthread " + FREDHOLM_BINARY +
                      " render --width 64 --height 64 --spp 1000000 -o " + dir + "/a.pfm >/dev/null 2>&1 &\n"
                      "pid=$!\n"
                      "for i in $(seq 300); do [ $(ls /proc/$pid/task | wc -l) -ge 2 ] && break; sleep 0.1; done\n"
                      "sleep 1\n"
                      "for t in /proc/$pid/task/*; do sed -n 's/^Cpus_allowed_list:[[:space:]]*//p' $t/status; done\n"
                      "kill $pid\n"
                      "wait $pid\n");
  const auto r = test::runCommand("sh " + dir + "/run.sh");
  std::vector<std::string> lines;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

TEST(DevicesCli, RenderKeepsEveryThreadOnTheCpusItWasGiven) {
  // Pinning PoCL's workers to CPUs 0..n-1 would move all but one off this CPU.
  const std::vector<int> allowed = allowedCpus();
  ASSERT_FALSE(allowed.empty()) << "this process's CPU mask could not be read";
  const std::string cpu = std::to_string(allowed.front());
  const auto cpus = renderThreadCpus("taskset -c " + cpu);
  ASSERT_GE(cpus.size(), 2u) << "the render's threads were not found";
  for (const std::string& c : cpus) EXPECT_EQ(c, cpu);
}

TEST(DevicesCli, RenderPinsPoclWorkersWhereItMayUseEveryCpu) {
  const std::vector<int> allowed = allowedCpus();
  ASSERT_FALSE(allowed.empty()) << "this process's CPU mask could not be read";
  const auto cpus = renderThreadCpus("");
  ASSERT_GE(cpus.size(), 2u) << "the render's threads were not found";
  if (cpuWorkersMayBePinned(allowed, sysconf(_SC_NPROCESSORS_ONLN))) {
    // Worker i runs on CPU i alone; the other threads keep the whole machine.
    for (int cpu : allowed)
      EXPECT_NE(std::find(cpus.begin(), cpus.end(), std::to_string(cpu)), cpus.end()) << "no thread pinned to " << cpu;
  } else if (allowed.size() > 1) {
    // A machine this process may use only part of (a container's cpuset): nothing is pinned.
    for (const std::string& c : cpus)
      EXPECT_FALSE(c.find_first_not_of("0123456789") == std::string::npos) << "a thread pinned to CPU " << c;
  }
}

}  // namespace
}  // namespace fh
