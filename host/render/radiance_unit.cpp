// Emission scaled into the renderer's unit (render/radiance_unit.h).
#include "render/radiance_unit.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "scene/environment_map.h"

namespace fh {
namespace {

// Emitters as bright as 2^-kRadianceBand to 2^kRadianceBand render in the scene's units.
constexpr int kRadianceBand = 10;

// The brightest emission: a light's Ke, --env, or --env-map's mean radiance (its texels'
// largest would let a sun disk set the unit for a dim sky).
double brightest(const Scene& scene, const RenderSettings& s) {
  double most = 0.0;
  for (const Light& light : scene.lights)
    for (float ke : scene.materials[size_t(scene.triangleMaterial[light.triangle])].ke) most = std::max(most, double(ke));
  for (float e : s.env) most = std::max(most, double(e));
  if (s.envMap) most = std::max(most, s.envMap->luminanceIntegral / (4.0 * M_PI));
  return most;
}

EnvironmentMap scaledMap(const EnvironmentMap& map, float factor) {
  EnvironmentMap scaled = map;
  for (size_t i = 0; i < scaled.texels.size(); i += 4)
    for (size_t c = 0; c < 3; ++c) scaled.texels[i + c] *= factor;  // not the density, [i + 3]
  scaled.scale *= factor;
  scaled.luminanceIntegral *= double(factor);
  return scaled;
}

}  // namespace

double toRadianceUnit(Scene& scene, RenderSettings& s) {
  const double most = brightest(scene, s);
  if (!(most > 0.0) || !std::isfinite(most)) return 1.0;
  const int exponent = std::clamp(std::ilogb(most), -126, 126);  // a float's normal exponents
  if (std::abs(exponent) <= kRadianceBand) return 1.0;
  const float factor = std::ldexp(1.f, -exponent);
  for (Material& m : scene.materials)
    for (float& ke : m.ke) ke *= factor;
  for (Light& light : scene.lights) {  // as collectLights has it, from the scaled Ke (exact)
    const Vec3f& ke = scene.materials[size_t(scene.triangleMaterial[light.triangle])].ke;
    const float k = float(M_PI) * light.area;
    light.power = {k * ke[0], k * ke[1], k * ke[2]};
  }
  for (float& e : s.env) e *= factor;
  if (s.envMap) s.envMap = std::make_shared<const EnvironmentMap>(scaledMap(*s.envMap, factor));
  return std::ldexp(1.0, exponent);
}

}  // namespace fh
