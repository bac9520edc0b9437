// Emission scaled into the renderer's unit (render/radiance_unit.h).
#include "render/radiance_unit.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "base/vec.h"
#include "scene/environment_map.h"

namespace fh {
namespace {

// Emitters whose brightness has an exponent within kRadianceBand of zero render in the
// scene's units (exponentTowardOne).
constexpr int kRadianceBand = 10;

// A light's Ke.
const Vec3f& emission(const Scene& scene, const Light& light) {
  return scene.materials[size_t(scene.triangleMaterial[light.triangle])].ke;
}

// The brightest emission: a light's Ke, --env, or --env-map's mean radiance (its texels'
// largest would let a sun disk set the unit for a dim sky).
double brightest(const Scene& scene, const RenderSettings& s) {
  double most = 0.0;
  for (const Light& light : scene.lights)
    for (float ke : emission(scene, light)) most = std::max(most, double(ke));
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
  // Clamped to a float's normal exponents, so that the factor is a normal float.
  const int exponent = std::clamp(exponentTowardOne(brightest(scene, s), kRadianceBand), -126, 126);
  if (exponent == 0) return 1.0;
  const float factor = std::ldexp(1.f, exponent);
  for (Material& m : scene.materials)
    for (float& ke : m.ke) ke *= factor;
  for (Light& light : scene.lights)  // from the scaled Ke: exact, and finite where the file's overflowed
    light.power = emittedPower(light.area, emission(scene, light));
  for (float& e : s.env) e *= factor;
  if (s.envMap) s.envMap = std::make_shared<const EnvironmentMap>(scaledMap(*s.envMap, factor));
  return std::ldexp(1.0, -exponent);
}

}  // namespace fh
