// Filters over an image's pixels, clipped at its edges: each value's mean, or largest, over
// the (2 radius + 1)^2 pixels around its own. Values are `channels` per pixel, interleaved, rows
// from the top (as Image::rgb); each channel is filtered apart.
#pragma once
#include <vector>

namespace fh {

std::vector<double> neighbourhoodMean(const std::vector<double>& values, int width, int height, int radius,
                                      int channels = 1);
std::vector<double> neighbourhoodMax(const std::vector<double>& values, int width, int height, int radius,
                                     int channels = 1);

}  // namespace fh
