// The film: every finished pass of a render, merged in pass order in double precision,
// whichever device rendered it. Per pixel it keeps the sum of samples (rgb, w: count)
// and the sum of their squares, from which the variance of the pixel's mean follows.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "image/image_io.h"

namespace fh {

struct Film {
  Film() = default;
  Film(int w, int h);

  // Adds one pass: per pixel (rgb, 1), pixel-major, as the device's pass buffer holds it.
  void addPass(const std::vector<float>& samples);

  Image image() const;  // the mean per pixel
  // The variance of the pixel's mean estimate, per channel (sample variance / count).
  std::array<double, 3> varianceOfMean(size_t pixel) const;
  double count(size_t pixel) const { return sum[4 * pixel + 3]; }
  size_t pixels() const { return size_t(width) * size_t(height); }

  int width = 0, height = 0;
  std::vector<double> sum, sumSq;
};

}  // namespace fh
