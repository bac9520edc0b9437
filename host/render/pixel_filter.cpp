// Filter shapes and their inverse CDFs.
#include "render/pixel_filter.h"

#include <algorithm>
#include <cmath>

namespace fh {
namespace {

double filterValue(PixelFilter f, double x, double radius) {
  switch (f) {
    case PixelFilter::Box:
      return 1.0;
    case PixelFilter::Gaussian: {  // sigma 0.5, shifted to reach zero at the radius
      const double sigma = 0.5;
      return std::max(0.0, std::exp(-x * x / (2 * sigma * sigma)) - std::exp(-radius * radius / (2 * sigma * sigma)));
    }
    case PixelFilter::BlackmanHarris: {
      const double t = (x + radius) / (2.0 * radius);  // 0..1 over the support
      return 0.35875 - 0.48829 * std::cos(2 * M_PI * t) + 0.14128 * std::cos(4 * M_PI * t) -
             0.01168 * std::cos(6 * M_PI * t);
    }
  }
  return 1.0;
}

double filterRadius(PixelFilter filter) {
  return filter == PixelFilter::Box ? 0.5 : filter == PixelFilter::Gaussian ? 1.5 : 2.0;
}

}  // namespace

std::vector<float> filterDensity(PixelFilter filter, int size) {
  const double r = filterRadius(filter), step = 2 * r / (size - 1);
  std::vector<double> values(size_t(size), 0.0);
  double integral = 0;
  for (int i = 0; i < size; ++i) {
    values[size_t(i)] = filterValue(filter, -r + i * step, r);
    integral += values[size_t(i)] * (i == 0 || i == size - 1 ? 0.5 : 1.0) * step;
  }
  std::vector<float> table(values.size());
  for (size_t i = 0; i < values.size(); ++i) table[i] = float(values[i] / integral);
  return table;
}

std::vector<float> filterInverseCdf(PixelFilter filter, int size, float* radius) {
  const double r = filterRadius(filter);
  *radius = float(r);
  // Integrate the filter finely, then invert the CDF at `size` evenly spaced values.
  const int steps = 4096;
  std::vector<double> cdf(steps + 1, 0.0);
  for (int i = 0; i < steps; ++i) {
    const double x = -r + (i + 0.5) * 2 * r / steps;
    cdf[size_t(i) + 1] = cdf[size_t(i)] + filterValue(filter, x, r);
  }
  std::vector<float> table(static_cast<size_t>(size));
  for (int j = 0; j < size; ++j) {
    const double target = cdf.back() * j / (size - 1);
    const auto it = std::lower_bound(cdf.begin(), cdf.end(), target);
    const size_t i = size_t(std::max<std::ptrdiff_t>(1, it - cdf.begin()));
    const double f = (target - cdf[i - 1]) / std::max(cdf[i] - cdf[i - 1], 1e-300);
    table[size_t(j)] = float(-r + (double(i - 1) + std::clamp(f, 0.0, 1.0)) * 2 * r / steps);
  }
  return table;
}

}  // namespace fh
