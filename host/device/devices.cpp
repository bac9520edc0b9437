// Device enumeration and selection for --device.
#include "device/devices.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <iomanip>
#include <set>
#include <sstream>

namespace fh {
namespace {

std::string typeName(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "gpu";
  if (type & CL_DEVICE_TYPE_CPU) return "cpu";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// Strips the trailing NUL some drivers leave in info strings.
std::string clean(std::string s) {
  while (!s.empty() && (s.back() == '\0' || s.back() == ' ')) s.pop_back();
  return s;
}

bool isIndexList(const std::string& spec) {
  return !spec.empty() && spec.find_first_not_of("0123456789, ") == std::string::npos;
}

std::string describeAvailable(const std::vector<DeviceInfo>& all) {
  std::ostringstream out;
  out << "available: ";
  for (size_t i = 0; i < all.size(); ++i) {
    if (i) out << "; ";
    out << all[i].index << " = " << all[i].name << " (" << all[i].type << ")";
  }
  out << " (see `fredholm devices`)";
  return out.str();
}

}  // namespace

bool cpuWorkersMayBePinned(const std::vector<int>& allowedCpus, long onlineCpus) {
  if (onlineCpus <= 0 || long(allowedCpus.size()) != onlineCpus) return false;
  std::vector<int> sorted = allowedCpus;
  std::sort(sorted.begin(), sorted.end());
  for (size_t i = 0; i < sorted.size(); ++i)
    if (sorted[i] != int(i)) return false;
  return true;
}

std::vector<int> allowedCpus() {
  cpu_set_t mask;
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof mask, &mask) != 0) return cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &mask)) cpus.push_back(cpu);
  return cpus;
}

void pinCpuWorkersWhereSafe() {
  for (const char* tuned : {"POCL_AFFINITY", "POCL_MAX_PTHREAD_COUNT", "POCL_CPU_MAX_CU_COUNT"})
    if (std::getenv(tuned)) return;
  if (cpuWorkersMayBePinned(allowedCpus(), sysconf(_SC_NPROCESSORS_ONLN))) setenv("POCL_AFFINITY", "1", 0);
}

std::vector<DeviceInfo> listDevices() {
  std::vector<cl::Platform> platforms;
  const cl_int err = cl::Platform::get(&platforms);
  if (err == -1001 || (err == CL_SUCCESS && platforms.empty()))
    throw Error("no OpenCL platform found: install an OpenCL driver (e.g. `apt-get install pocl-opencl-icd`)");
  FH_CL_ERR(err, "clGetPlatformIDs");

  std::vector<DeviceInfo> result;
  for (const auto& platform : platforms) {
    std::vector<cl::Device> devices;
    const cl_int derr = platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    if (derr == CL_DEVICE_NOT_FOUND) continue;
    FH_CL_ERR(derr, "clGetDeviceIDs");
    for (const auto& device : devices) {
      DeviceInfo info;
      info.index = static_cast<int>(result.size());
      info.platform = platform;
      info.device = device;
      info.platformName = clean(platform.getInfo<CL_PLATFORM_NAME>());
      info.name = clean(device.getInfo<CL_DEVICE_NAME>());
      info.vendor = clean(device.getInfo<CL_DEVICE_VENDOR>());
      info.type = typeName(device.getInfo<CL_DEVICE_TYPE>());
      info.openclCVersion = clean(device.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
      info.driverVersion = clean(device.getInfo<CL_DRIVER_VERSION>());
      info.computeUnits = device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      info.globalMemory = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      result.push_back(info);
    }
  }
  if (result.empty()) throw Error("no OpenCL device found on any platform");
  return result;
}

std::vector<DeviceInfo> selectDevices(const std::vector<DeviceInfo>& all, const std::string& rawSpec) {
  const std::string spec = lower(trim(rawSpec));
  std::vector<DeviceInfo> chosen;
  if (spec.empty()) {
    auto gpu = std::find_if(all.begin(), all.end(), [](const DeviceInfo& d) { return d.type == "gpu"; });
    chosen.push_back(gpu != all.end() ? *gpu : all.front());
    return chosen;
  }
  if (spec == "all") return all;

  if (isIndexList(spec)) {
    std::set<int> seen;
    std::istringstream items(spec);
    std::string item;
    while (std::getline(items, item, ',')) {
      item = trim(item);
      if (item.empty()) throw Error("--device '" + rawSpec + "': empty entry in the index list");
      const long index = std::stol(item);
      if (index < 0 || index >= static_cast<long>(all.size()))
        throw Error("--device '" + rawSpec + "': no device with index " + item + "; " +
                    describeAvailable(all));
      if (seen.insert(static_cast<int>(index)).second) chosen.push_back(all[static_cast<size_t>(index)]);
    }
    return chosen;
  }

  const bool isType = spec == "cpu" || spec == "gpu" || spec == "accelerator";
  for (const auto& d : all) {
    const bool match = isType ? d.type == spec : lower(d.name).find(spec) != std::string::npos ||
                                                     lower(d.vendor).find(spec) != std::string::npos;
    if (match) chosen.push_back(d);
  }
  if (chosen.empty())
    throw Error("--device '" + rawSpec + "' matches no " + (isType ? "device of that type" : "device name") +
                "; " + describeAvailable(all));
  return chosen;
}

std::string formatDeviceTable(const std::vector<DeviceInfo>& devices) {
  std::ostringstream out;
  out << std::left << std::setw(6) << "index" << std::setw(6) << "type" << std::setw(50) << "name"
      << std::setw(36) << "vendor" << std::setw(14) << "OpenCL C" << std::right << std::setw(6) << "CUs"
      << std::setw(12) << "memory" << "  platform\n";
  for (const auto& d : devices) {
    std::ostringstream mem;
    mem << std::fixed << std::setprecision(1) << d.globalMemory / double(1ull << 30) << " GiB";
    out << std::left << std::setw(6) << d.index << std::setw(6) << d.type << std::setw(50) << d.name
        << std::setw(36) << d.vendor << std::setw(14) << d.openclCVersion << std::right
        << std::setw(6) << d.computeUnits << std::setw(12) << mem.str() << "  " << d.platformName << "\n";
  }
  return out.str();
}

}  // namespace fh
