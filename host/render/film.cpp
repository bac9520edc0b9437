// Merging passes and reading the film out.
#include "render/film.h"

#include <algorithm>

namespace fh {

Film::Film(int w, int h) : width(w), height(h), sum(pixels() * 4, 0.0), sumSq(pixels() * 4, 0.0) {}

void Film::addPass(const std::vector<float>& samples) {
  for (size_t i = 0; i < sum.size(); ++i) {
    const double v = samples[i];
    sum[i] += v;
    if (i % 4 != 3) sumSq[i] += v * v;
  }
}

Image Film::image() const {
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.resize(pixels() * 3);
  for (size_t p = 0; p < pixels(); ++p)
    for (size_t c = 0; c < 3; ++c) img.rgb[3 * p + c] = count(p) > 0 ? float(sum[4 * p + c] / count(p)) : 0.f;
  return img;
}

std::array<double, 3> Film::varianceOfMean(size_t p) const {
  const double n = count(p);
  std::array<double, 3> v{0, 0, 0};
  if (n < 2) return v;
  for (size_t c = 0; c < 3; ++c) {
    const double mean = sum[4 * p + c] / n;
    const double sampleVariance = std::max(0.0, (sumSq[4 * p + c] - n * mean * mean) / (n - 1));
    v[c] = sampleVariance / n;
  }
  return v;
}

}  // namespace fh
