// Program assembly, build with build-log reporting, and the binary cache.
#include "device/program.h"

#include "base/atomic_file.h"

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "device/kernel_sources.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

const std::map<std::string, const char*>& embeddedFileMap() {
  static const std::map<std::string, const char*> files = [] {
    std::map<std::string, const char*> m;
    for (const auto& f : embeddedFiles()) m[f.path] = f.text;
    return m;
  }();
  return files;
}

const char* findKernelFile(const std::string& name) { return embeddedFile("kernels/" + name); }

// Returns the included name if `line` is `#include "name"`, else "".
std::string quotedInclude(const std::string& line) {
  std::istringstream in(line);
  std::string hash, name;
  in >> hash;
  if (hash == "#include") {
    in >> name;
  } else if (hash == "#") {
    std::string word;
    in >> word >> name;
    if (word != "include") return "";
  } else {
    return "";
  }
  if (name.size() < 3 || name.front() != '"' || name.back() != '"') return "";
  return name.substr(1, name.size() - 2);
}

void appendFile(const std::string& name, std::set<std::string>& included, std::ostringstream& out) {
  if (!included.insert(name).second) return;
  std::istringstream in(findKernelFile(name));
  std::string line;
  int lineNumber = 0;
  out << "#line 1 \"kernels/" << name << "\"\n";
  while (std::getline(in, line)) {
    ++lineNumber;
    const std::string include = quotedInclude(line);
    if (include.empty()) {
      out << line << "\n";
      continue;
    }
    appendFile(include, included, out);
    out << "#line " << lineNumber + 1 << " \"kernels/" << name << "\"\n";
  }
}

// 128-bit FNV-1a (two 64-bit lanes with different offsets): a content key, not security.
std::string contentHash(const std::string& text) {
  uint64_t a = 0xcbf29ce484222325ull, b = 0x84222325cbf29ce4ull;
  for (unsigned char c : text) {
    a = (a ^ c) * 0x100000001b3ull;
    b = (b ^ c) * 0x100000001b3ull;
    b ^= b >> 29;
  }
  std::ostringstream out;
  out << std::hex << std::setfill('0') << std::setw(16) << a << std::setw(16) << b;
  return out.str();
}

std::string cacheKey(const cl::Device& device, const std::string& source, const std::string& options) {
  cl::Platform platform(device.getInfo<CL_DEVICE_PLATFORM>());
  std::ostringstream key;
  key << platform.getInfo<CL_PLATFORM_NAME>() << '\n'
      << platform.getInfo<CL_PLATFORM_VERSION>() << '\n'
      << device.getInfo<CL_DEVICE_NAME>() << '\n'
      << device.getInfo<CL_DEVICE_VERSION>() << '\n'
      << device.getInfo<CL_DRIVER_VERSION>() << '\n'
      << options << '\n'
      << source;
  return contentHash(key.str());
}

std::string buildLog(const cl::Program& program, const cl::Device& device) {
  std::string log;
  program.getBuildInfo(device, CL_PROGRAM_BUILD_LOG, &log);
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

void buildOrThrow(cl::Program& program, const cl::Device& device, const std::string& options) {
  const cl_int err = program.build(std::vector<cl::Device>{device}, options.c_str());
  if (err == CL_BUILD_PROGRAM_FAILURE || err == CL_INVALID_BINARY) {
    throw BuildError("kernel build failed on " + device.getInfo<CL_DEVICE_NAME>() +
                     "; build log:\n" + buildLog(program, device));
  }
  FH_CL_ERR(err, "clBuildProgram");
}

bool loadCached(const cl::Context& context, const cl::Device& device, const std::string& path,
                const std::string& options, cl::Program& program) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::vector<unsigned char> binary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (binary.empty()) return false;
  cl_int err = CL_SUCCESS;
  std::vector<cl_int> status;
  cl::Program cached(context, {device}, cl::Program::Binaries{binary}, &status, &err);
  if (err != CL_SUCCESS) return false;
  // A stale or foreign binary is not an error: fall back to compiling from source.
  if (cached.build(std::vector<cl::Device>{device}, options.c_str()) != CL_SUCCESS) return false;
  program = cached;
  return true;
}

void storeCached(const cl::Program& program, const std::string& path) {
  std::vector<std::vector<unsigned char>> binaries;
  if (program.getInfo(CL_PROGRAM_BINARIES, &binaries) != CL_SUCCESS || binaries.size() != 1 ||
      binaries[0].empty())
    return;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec) return;  // an unwritable cache only costs a recompile next time
  try {  // whole or not at all, like every file fredholm writes
    writeTextAtomically(path, "program cache",
                        std::string(reinterpret_cast<const char*>(binaries[0].data()), binaries[0].size()));
  } catch (const Error&) {
  }
}

}  // namespace

const char* embeddedFile(const std::string& path) {
  const auto& files = embeddedFileMap();
  const auto it = files.find(path);
  if (it == files.end()) throw Error("'" + path + "' is not embedded in this build");
  return it->second;
}

std::string assembleKernelSources(const std::vector<std::string>& files) {
  std::set<std::string> included;
  std::ostringstream out;
  for (const auto& f : files) appendFile(f, included, out);
  return out.str();
}

std::string assembleKernelSource(const std::string& file) { return assembleKernelSources({file}); }

std::string programCacheDir() {
  if (const char* dir = std::getenv("FREDHOLM_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/fredholm";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/fredholm";
  return "";
}

std::string extraBuildOptions() {
  const char* extra = std::getenv("FREDHOLM_CL_OPTIONS");
  return extra && *extra ? std::string(" ") + extra : "";
}

cl::Program buildProgramFromSource(const cl::Context& context, const cl::Device& device,
                                   const std::string& source, const std::string& programOptions,
                                   ProgramBuildInfo* info) {
  const auto start = std::chrono::steady_clock::now();
  const std::string options = programOptions + extraBuildOptions();
  const std::string dir = programCacheDir();
  const std::string path = dir.empty() ? "" : dir + "/" + cacheKey(device, source, options) + ".bin";
  cl::Program program;
  bool fromCache = !path.empty() && loadCached(context, device, path, options, program);
  if (!fromCache) {
    cl_int err = CL_SUCCESS;
    program = cl::Program(context, source, false, &err);
    FH_CL_ERR(err, "clCreateProgramWithSource");
    buildOrThrow(program, device, options);
    if (!path.empty()) storeCached(program, path);
  }
  if (info) {
    info->fromCache = fromCache;
    info->cacheFile = path;
    info->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return program;
}

cl::Program buildProgram(const cl::Context& context, const cl::Device& device,
                         const std::vector<std::string>& files, const std::string& options,
                         ProgramBuildInfo* info) {
  return buildProgramFromSource(context, device, assembleKernelSources(files), options, info);
}

cl::Program buildProgram(const cl::Context& context, const cl::Device& device, const ProgramSpec& spec,
                         ProgramBuildInfo* info) {
  return buildProgram(context, device, spec.files, spec.options, info);
}

cl::Kernel createKernel(const cl::Program& program, const char* name) {
  cl_int err = CL_SUCCESS;
  cl::Kernel kernel(program, name, &err);
  FH_CL_ERR(err, (std::string("clCreateKernel(") + name + ")").c_str());
  return kernel;
}

}  // namespace fh
