// Shared by the fuzz targets: a private scratch directory for the files an input becomes
// (the loaders read files, as the command line does).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

namespace fh::fuzz {

inline const std::string& scratchDir() {
  static const std::string dir = [] {
    std::string pattern = "/tmp/fredholm-fuzz-XXXXXX";
    if (!::mkdtemp(&pattern[0])) std::abort();
    return pattern;
  }();
  return dir;
}

inline std::string writeScratch(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratchDir() + "/" + name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                               std::streamsize(size));
  return path;
}

}  // namespace fh::fuzz
