// An HDR environment map: radiance arriving from infinitely far away in every direction,
// stored as a latitude-longitude image, with the tables that light sampling draws
// directions from (a piecewise-constant 2D distribution over the image, in proportion to
// luminance times sin(theta), so it follows the radiance per solid angle).
//
// Directions, with +y up: row 0 is straight up (theta = 0), the last row straight down;
// column u = 0.5 looks along -z (the way the default camera looks), and u grows towards +x,
// so the map seen from inside is the image as it is drawn, not mirrored. Rotating the map
// by a degrees turns it about +y, counter-clockwise seen from above (right-handed).
#pragma once
#include <string>
#include <vector>

namespace fh {

struct EnvironmentMap {
  std::string source;  // the file, or a description for maps made in memory
  int width = 0, height = 0;
  float rotateDeg = 0.f, scale = 1.f;
  // Per texel: scaled linear RGB radiance, then the sampling density per unit (u, v) area
  // of that texel (zero where the texel is black).
  std::vector<float> texels;
  std::vector<float> rowCdf;       // per row, the CDF over its columns (width per row)
  std::vector<float> marginalCdf;  // the CDF over rows
  double luminanceIntegral = 0.0;  // the luminance integrated over the sphere (per steradian)

  // u offset of the map's column 0 for the rotation, in [0, 1): lookups add it to a
  // direction's u.
  float uShift() const;
  // Everything the kernels read, in the order kernels/environment.h expects: texels, row
  // CDFs, marginal CDF.
  std::vector<float> packed() const;
};

// A map from linear RGB rows (width * height * 3 floats, row 0 at the top). Negative or
// non-finite radiance, or a rotation or scale that is not finite, throws fh::Error naming
// `source` and the texel.
EnvironmentMap makeEnvironmentMap(const std::string& source, int width, int height, const std::vector<float>& rgb,
                                  float rotateDeg, float scale);

// Reads an .exr or .hdr latitude-longitude map through OpenImageIO; throws fh::Error with
// the file's name.
EnvironmentMap loadEnvironmentMap(const std::string& path, float rotateDeg, float scale);

}  // namespace fh
