// Camera files: any text must parse to a valid camera or throw fh::Error.
#include <cmath>
#include <string>

#include "base/error.h"
#include "scene/camera.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const fh::Camera c = fh::parseCameraJson(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const fh::CameraFrame f = fh::makeCameraFrame(c, 16, 16);
    for (float v : f.forward)
      if (!std::isfinite(v)) __builtin_trap();  // a camera accepted must give finite rays
  } catch (const fh::Error&) {
  }
  return 0;
}
