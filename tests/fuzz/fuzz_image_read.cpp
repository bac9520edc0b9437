// Image reading, as `fredholm compare` does it: the first byte picks the extension the
// rest is saved under (.pfm, .exr, .png, .hdr); any file must read or throw fh::Error.
#include <string>

#include "base/error.h"
#include "fuzz_support.h"
#include "image/error_metrics.h"
#include "image/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* extensions[] = {".pfm", ".exr", ".png", ".hdr"};
  const std::string path = fh::fuzz::writeScratch(std::string("image") + extensions[data[0] % 4], data + 1, size - 1);
  try {
    const fh::Image image = fh::readImage(path);
    fh::imageError(image, image);
  } catch (const fh::Error&) {
  }
  return 0;
}
