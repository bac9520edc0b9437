// Image error against a reference, the one definition the convergence charts and the
// tests share: relMSE (per pixel and channel (x - r)^2 / (r^2 + 0.01), averaged), RMSE and
// mean absolute error, over linear radiance.
#pragma once
#include <array>
#include <cstddef>
#include <string>

#include "image/image_io.h"

namespace fh {

// The epsilon of relMSE's denominator: keeps near-black pixels from dominating it.
constexpr double kRelMseEpsilon = 0.01;

struct ImageError {
  double relMse = 0.0, rmse = 0.0, mae = 0.0;
  // Per-channel means of both images: their ratio is the overall bias, which the
  // per-pixel metrics mix with noise.
  std::array<double, 3> meanImage{}, meanReference{};
};

// Throws fh::Error if the sizes differ.
ImageError imageError(const Image& image, const Image& reference);

// The image's channel values that are not finite: how many, and the first pixel (in rows
// from the top) holding one, if any.
struct NonFiniteValues {
  size_t count = 0, firstPixel = 0;
};
NonFiniteValues nonFiniteValues(const Image& image);

// Throws fh::Error, "SOURCE: pixel (x, y) ...", naming the first pixel (in rows from the top)
// with a channel that is not finite: metrics over it would be NaN or infinite.
void requireFinite(const Image& image, const std::string& source);

// The image averaged over k x k pixel blocks: comparing block averages separates a bias
// that covers a region from per-pixel noise (k^2 times less of it). Throws fh::Error
// unless k >= 1 divides both sides.
Image blockAverage(const Image& image, int k);

}  // namespace fh
