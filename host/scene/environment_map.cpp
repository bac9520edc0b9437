// Environment maps: reading, checking, and the sampling tables.
#include "scene/environment_map.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "base/error.h"
#include "image/image_io.h"

namespace fh {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string shortNumber(float v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// Running sums of `weights` divided by their total, the last exactly 1; uniform when the
// total is zero (the row is never picked then, but its table stays well formed).
void appendCdf(const std::vector<double>& weights, std::vector<float>& cdf) {
  double total = 0.0;
  for (double w : weights) total += w;
  double running = 0.0;
  for (size_t i = 0; i < weights.size(); ++i) {
    running += weights[i];
    cdf.push_back(total > 0.0 ? float(running / total) : float(double(i + 1) / double(weights.size())));
  }
  cdf.back() = 1.f;
}

}  // namespace

float EnvironmentMap::uShift() const {
  const double turns = double(rotateDeg) / 360.0;
  return float(turns - std::floor(turns));
}

std::vector<float> EnvironmentMap::packed() const {
  std::vector<float> out(texels);
  out.insert(out.end(), rowCdf.begin(), rowCdf.end());
  out.insert(out.end(), marginalCdf.begin(), marginalCdf.end());
  return out;
}

EnvironmentMap makeEnvironmentMap(const std::string& source, int width, int height, const std::vector<float>& rgb,
                                  float rotateDeg, float scale) {
  if (!std::isfinite(rotateDeg)) throw Error("--env-rotate must be a finite number of degrees");
  if (!std::isfinite(scale) || scale < 0.f) throw Error("--env-scale must be a finite, non-negative factor");
  if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * size_t(height) * 3)
    throw Error(source + ": not a latitude-longitude image");
  EnvironmentMap map;
  map.source = source;
  map.width = width;
  map.height = height;
  map.rotateDeg = rotateDeg;
  map.scale = scale;
  map.texels.resize(size_t(width) * size_t(height) * 4);
  // Texel i's weight in row y: its luminance times sin(theta) at the row's centre, the
  // texel's solid angle up to a constant.
  auto weightOf = [&](size_t i, int y) {
    return std::max(0.0, luminance(&map.texels[4 * i])) * std::sin(kPi * (y + 0.5) / height);
  };
  std::vector<double> rowWeights(static_cast<size_t>(height)), weights(static_cast<size_t>(width));
  double total = 0.0;
  for (int y = 0; y < height; ++y) {
    double rowTotal = 0.0;
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * size_t(width) + size_t(x);
      for (size_t c = 0; c < 3; ++c) {
        const float v = rgb[3 * i + c];
        if (!std::isfinite(v) || v < 0.f)
          throw Error(source + ": texel (" + std::to_string(x) + ", " + std::to_string(y) +
                      ") holds a negative or non-finite radiance");
        map.texels[4 * i + c] = v * scale;
        if (!std::isfinite(map.texels[4 * i + c]))
          throw Error(source + ": texel (" + std::to_string(x) + ", " + std::to_string(y) +
                      ") is past the float range " + "once multiplied by --env-scale " + shortNumber(scale));
      }
      weights[size_t(x)] = weightOf(i, y);
      rowTotal += weights[size_t(x)];
    }
    appendCdf(weights, map.rowCdf);
    rowWeights[size_t(y)] = rowTotal;
    total += rowTotal;
  }
  appendCdf(rowWeights, map.marginalCdf);
  // A texel's density per unit (u, v) area: its share of the total times the texel count.
  // Black texels (and a black map) get none: light sampling never picks them.
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * size_t(width) + size_t(x);
      map.texels[4 * i + 3] = total > 0.0 ? float(weightOf(i, y) / total * double(width) * double(height)) : 0.f;
    }
  // The solid angle of a texel is (2 pi / width)(pi / height) sin(theta).
  map.luminanceIntegral = total * 2.0 * kPi * kPi / (double(width) * double(height));
  return map;
}

EnvironmentMap loadEnvironmentMap(const std::string& path, float rotateDeg, float scale) {
  const std::string ext = extensionOf(path);
  if (ext != ".exr" && ext != ".hdr")
    throw Error("--env-map '" + path + "': an environment map must be an .exr or .hdr latitude-longitude image");
  const Image image = readImage(path, "--env-map");
  return makeEnvironmentMap(path, image.width, image.height, image.rgb, rotateDeg, scale);
}

}  // namespace fh
