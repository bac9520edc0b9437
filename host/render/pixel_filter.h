// The pixel filter of the measurement equation, importance-sampled: generate offsets a
// sample from its pixel's centre through the filter's inverse CDF, so every sample has
// weight one and a pixel's estimate is the plain mean of its samples.
#pragma once
#include <vector>

#include "render/settings.h"

namespace fh {

// The filter's 1D inverse CDF over [-radius, radius], `size` entries (separable filters).
std::vector<float> filterInverseCdf(PixelFilter filter, int size, float* radius);

// The filter's 1D density over [-radius, radius] at `size` evenly spaced points, scaled so
// that its linear interpolation integrates to one: the weights light tracing splats with
// (kernels/light_trace.cl), where a sample lands at a position rather than in a pixel.
std::vector<float> filterDensity(PixelFilter filter, int size);

}  // namespace fh
