// Building OpenCL programs from the embedded kernels, with an on-disk binary cache keyed
// by (platform, device, driver version, source hash, build options).
#pragma once
#include <string>
#include <vector>

#include "device/cl_core.h"

namespace fh {

struct ProgramBuildInfo {
  bool fromCache = false;
  double seconds = 0.0;  // wall time to get a ready program, cache lookup included
  std::string cacheFile;
};

// Where program binaries are cached: $FREDHOLM_CACHE_DIR, else $XDG_CACHE_HOME/fredholm,
// else ~/.cache/fredholm. Empty when none can be determined.
std::string programCacheDir();

// One OpenCL program: the kernel files it is assembled from and the options that select
// its variant. Each module declares its programs once (tests/program_catalog.cpp lists them all).
struct ProgramSpec {
  std::string name;
  std::vector<std::string> files;
  std::string options;
};

// Options appended to every program build: $FREDHOLM_CL_OPTIONS (e.g. -cl-opt-disable for
// a portability check or a simulator that cannot run optimised code), else nothing.
std::string extraBuildOptions();

// Builds `files` (names under kernels/) for one device. A compile failure throws
// fh::BuildError whose message holds the device's build log.
cl::Program buildProgram(const cl::Context& context, const cl::Device& device,
                         const std::vector<std::string>& files, const std::string& options,
                         ProgramBuildInfo* info = nullptr);

// Same, from source text already assembled (tests use this to build bad sources).
cl::Program buildProgramFromSource(const cl::Context& context, const cl::Device& device,
                                   const std::string& source, const std::string& options,
                                   ProgramBuildInfo* info = nullptr);

cl::Program buildProgram(const cl::Context& context, const cl::Device& device, const ProgramSpec& spec,
                         ProgramBuildInfo* info = nullptr);

cl::Kernel createKernel(const cl::Program& program, const char* name);

}  // namespace fh
