// OpenCL device discovery and the --device SPEC grammar: an index (0), a list (0,1),
// a type (cpu, gpu, accelerator, all) or a case-insensitive name substring.
#pragma once
#include <string>
#include <vector>

#include "device/cl_core.h"

namespace fh {

struct DeviceInfo {
  int index = 0;  // position in the flat list over all platforms
  cl::Platform platform;
  cl::Device device;
  std::string platformName;
  std::string name;
  std::string vendor;
  std::string type;  // "cpu", "gpu", "accelerator", "other"
  std::string openclCVersion;
  std::string driverVersion;
  unsigned computeUnits = 0;
  unsigned long long globalMemory = 0;
};

// Every device of every platform; throws fh::Error when there is no OpenCL platform.
std::vector<DeviceInfo> listDevices();

// The devices a spec picks out of `all`, in the order the spec names them, without
// repeats. An empty spec picks the default: the first GPU, else the first device.
// Throws fh::Error naming the spec and the devices that exist when nothing matches.
std::vector<DeviceInfo> selectDevices(const std::vector<DeviceInfo>& all, const std::string& spec);

// The table `fredholm devices` prints.
std::string formatDeviceTable(const std::vector<DeviceInfo>& devices);

// The CPUs this process may run on (its affinity mask), in increasing order; empty if the
// mask cannot be read.
std::vector<int> allowedCpus();

// Whether PoCL's CPU driver may pin worker i to CPU i (POCL_AFFINITY=1) and keep every worker
// inside the CPUs this process may run on: only where those are all the machine's online
// CPUs, numbered 0 to n - 1. Elsewhere (taskset, mpirun --bind-to, a container's cpuset)
// pinning would move workers onto CPUs the user kept it off.
bool cpuWorkersMayBePinned(const std::vector<int>& allowedCpus, long onlineCpus);

// Sets POCL_AFFINITY=1 where cpuWorkersMayBePinned allows it and the user has tuned none of
// PoCL's CPU threads (POCL_AFFINITY, POCL_MAX_PTHREAD_COUNT, POCL_CPU_MAX_CU_COUNT unset).
// Unpinned, the OS may leave two workers on one core for a while after the cores were busy
// with other threads, which slows a kernel by tens of percent at random (bench/RESULTS.md).
// Call before the first OpenCL call and before any other thread starts.
void pinCpuWorkersWhereSafe();

}  // namespace fh
