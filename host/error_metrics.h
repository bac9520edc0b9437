// Image error against a reference, the one definition the convergence charts and the
// tests share: relMSE (per pixel and channel (x - r)^2 / (r^2 + 0.01), averaged), RMSE and
// mean absolute error, over linear radiance.
#pragma once
#include "image_io.h"

namespace fh {

struct ImageError {
  double relMse = 0.0, rmse = 0.0, mae = 0.0;
};

// Throws fh::Error if the sizes differ.
ImageError imageError(const Image& image, const Image& reference);

}  // namespace fh
