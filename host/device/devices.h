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

}  // namespace fh
