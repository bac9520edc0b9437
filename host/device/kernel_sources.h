// Kernel sources embedded at build time (cmake/embed_kernels.cmake), and the assembly of
// one program's source: #include "x.h" lines are inlined once each, with #line markers,
// so compiler messages name the real file and line under kernels/.
#pragma once
#include <string>
#include <vector>

namespace fh {

struct EmbeddedFile {
  const char* path;  // relative to the repository, e.g. "kernels/intersect.cl"
  const char* text;
};

// Every embedded file: kernels/* and the built-in scene under scenes/.
const std::vector<EmbeddedFile>& embeddedFiles();

// The text of an embedded file by its repository path; throws fh::Error if absent.
const char* embeddedFile(const std::string& path);

// `file` is a name under kernels/ ("intersect.cl"). Throws fh::Error if it or an
// included file is not embedded.
std::string assembleKernelSource(const std::string& file);

// Assembles several top-level files into one program (each inlining its includes once).
std::string assembleKernelSources(const std::vector<std::string>& files);

}  // namespace fh
