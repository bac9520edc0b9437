// Error metrics.
#include "error_metrics.h"

#include <cmath>

#include "error.h"

namespace fh {

ImageError imageError(const Image& image, const Image& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw Error("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", reference " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height));
  ImageError e;
  const size_t n = image.rgb.size();
  for (size_t i = 0; i < n; ++i) {
    const double d = double(image.rgb[i]) - double(reference.rgb[i]), r = reference.rgb[i];
    e.relMse += d * d / (r * r + 0.01);
    e.rmse += d * d;
    e.mae += std::fabs(d);
  }
  e.relMse /= double(n);
  e.rmse = std::sqrt(e.rmse / double(n));
  e.mae /= double(n);
  return e;
}

}  // namespace fh
