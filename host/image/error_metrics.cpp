// Error metrics.
#include "image/error_metrics.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "base/error.h"

namespace fh {

ImageError imageError(const Image& image, const Image& reference) {
  if (image.width != reference.width || image.height != reference.height)
    throw Error("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", reference " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height));
  ImageError e;
  const size_t n = image.rgb.size();
  for (size_t i = 0; i < n; ++i) {
    const double d = double(image.rgb[i]) - double(reference.rgb[i]), r = reference.rgb[i];
    e.relMse += d * d / (r * r + kRelMseEpsilon);
    e.rmse += d * d;
    e.mae += std::fabs(d);
    e.meanImage[i % 3] += image.rgb[i];
    e.meanReference[i % 3] += reference.rgb[i];
  }
  for (int c = 0; c < 3; ++c) {
    e.meanImage[size_t(c)] /= double(n / 3);
    e.meanReference[size_t(c)] /= double(n / 3);
  }
  e.relMse /= double(n);
  e.rmse = std::sqrt(e.rmse / double(n));
  e.mae /= double(n);
  return e;
}

NonFiniteValues nonFiniteValues(const Image& image) {
  NonFiniteValues found;
  const size_t pixels = size_t(image.width) * size_t(image.height);
  for (size_t p = 0; p < pixels && 3 * p + 2 < image.rgb.size(); ++p)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(image.rgb[3 * p + size_t(c)]) && found.count++ == 0) found.firstPixel = p;
  return found;
}

void requireFinite(const Image& image, const std::string& source) {
  const NonFiniteValues found = nonFiniteValues(image);
  if (found.count == 0) return;
  const size_t p = found.firstPixel;
  std::string values;
  for (int c = 0; c < 3; ++c) {
    std::ostringstream v;
    v << image.rgb[3 * p + size_t(c)];
    values += (c ? " " : "") + v.str();
  }
  throw Error(source + ": pixel (" + std::to_string(p % size_t(image.width)) + ", " +
              std::to_string(p / size_t(image.width)) + ") is not finite (" + values +
              "); metrics need finite radiance everywhere");
}

Image blockAverage(const Image& image, int k) {
  if (k < 1 || image.width % k != 0 || image.height % k != 0)
    throw Error("block size " + std::to_string(k) + " does not divide the image (" + std::to_string(image.width) +
                "x" + std::to_string(image.height) + ")");
  Image out;
  out.width = image.width / k;
  out.height = image.height / k;
  out.rgb.assign(size_t(out.width) * size_t(out.height) * 3, 0.f);
  std::vector<double> sum(out.rgb.size(), 0.0);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c)
        sum[size_t(3 * ((y / k) * out.width + x / k) + c)] += image.rgb[size_t(3 * (y * image.width + x) + c)];
  for (size_t i = 0; i < sum.size(); ++i) out.rgb[i] = float(sum[i] / double(k * k));
  return out;
}

}  // namespace fh
