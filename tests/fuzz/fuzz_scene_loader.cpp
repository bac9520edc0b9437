// The OBJ/MTL loader and its lint. An input is an OBJ, optionally followed by "\n@MTL\n"
// and the MTL the OBJ's `mtllib scene.mtl` names. Any input must load or throw fh::Error;
// a crash, a sanitizer report, a hang or unbounded memory is a bug.
#include <string>

#include "base/error.h"
#include "fuzz_support.h"
#include "scene/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t split = input.find("\n@MTL\n");
  const std::string obj = input.substr(0, split);
  const std::string mtl = split == std::string::npos ? "" : input.substr(split + 6);
  fh::fuzz::writeScratch("scene.mtl", reinterpret_cast<const uint8_t*>(mtl.data()), mtl.size());
  const std::string path = fh::fuzz::writeScratch("scene.obj", reinterpret_cast<const uint8_t*>(obj.data()), obj.size());
  try {
    const fh::Scene scene = fh::loadScene(path);
    // What the renderer relies on: every index names a vertex, every triangle a material.
    for (unsigned i : scene.indices)
      if (i >= scene.vertexCount()) __builtin_trap();
    for (int m : scene.triangleMaterial)
      if (m < 0 || size_t(m) >= scene.materials.size()) __builtin_trap();
  } catch (const fh::Error&) {
  }
  return 0;
}
