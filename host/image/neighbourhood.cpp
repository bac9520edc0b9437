#include "image/neighbourhood.h"

#include <algorithm>

namespace fh {
namespace {

// Along x, then along y (the block is a rectangle after clipping, so the mean of the rows'
// means is the block's mean).
std::vector<double> separable(const std::vector<double>& in, int width, int height, int radius, int channels,
                              bool mean) {
  const auto at = [width, channels](int x, int y, int c) {
    return (size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + size_t(c);
  };
  std::vector<double> across(in.size()), out(in.size());
  for (int dir = 0; dir < 2; ++dir) {
    const std::vector<double>& from = dir == 0 ? in : across;
    std::vector<double>& to = dir == 0 ? across : out;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < channels; ++c) {
          double total = 0.0, most = 0.0;
          int n = 0;
          for (int d = -radius; d <= radius; ++d) {
            const int nx = dir == 0 ? x + d : x, ny = dir == 0 ? y : y + d;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            total += from[at(nx, ny, c)];
            most = std::max(most, from[at(nx, ny, c)]);
            ++n;
          }
          to[at(x, y, c)] = mean ? total / n : most;
        }
  }
  return out;
}

}  // namespace

std::vector<double> neighbourhoodMean(const std::vector<double>& values, int width, int height, int radius,
                                      int channels) {
  return separable(values, width, height, radius, channels, true);
}

std::vector<double> neighbourhoodMax(const std::vector<double>& values, int width, int height, int radius,
                                     int channels) {
  return separable(values, width, height, radius, channels, false);
}

}  // namespace fh
