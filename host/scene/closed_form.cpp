// Closed-form scenes and their exact images.
#include "scene/closed_form.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "scene/camera.h"
#include "scene/scene_loader.h"

namespace fh {

double lambertIrradiance(const float3& x, const float3& n, const std::vector<float3>& polygon, double le) {
  double sum = 0;
  for (size_t k = 0; k < polygon.size(); ++k) {
    const float3 a = normalize(polygon[k] - x), b = normalize(polygon[(k + 1) % polygon.size()] - x);
    const double theta = std::acos(std::clamp(double(dot(a, b)), -1.0, 1.0));
    sum += theta * dot(normalize(cross(a, b)), n);
  }
  return 0.5 * le * std::fabs(sum);
}

std::vector<float3> PlaneUnderLight::light() {
  const float s = kLightHalf, h = kHeight;
  return {{-s, h, -s}, {s, h, -s}, {s, h, s}, {-s, h, s}};  // counter-clockwise seen from below
}

Scene PlaneUnderLight::scene() {
  Scene s;
  s.sourcePath = "builtin:plane-under-light";
  Material plane, emitter;
  plane.name = "plane";
  plane.kd = {kRho, kRho, kRho};
  plane.illum = 1;
  emitter.name = "light";
  emitter.kd = {0, 0, 0};
  emitter.ke = {kLe, kLe, kLe};
  s.materials = {plane, emitter};
  const float p = kPlaneHalf;
  const std::vector<float3> quads[2] = {{{-p, 0, -p}, {-p, 0, p}, {p, 0, p}, {p, 0, -p}}, light()};
  for (int q = 0; q < 2; ++q) {
    const unsigned base = unsigned(s.vertexCount());
    for (const float3& v : quads[q]) s.positions.insert(s.positions.end(), v.begin(), v.end());
    for (unsigned k : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + k);
    s.triangleMaterial.insert(s.triangleMaterial.end(), {q, q});
  }
  collectLights(s);
  s.hasCamera = true;
  s.camera.eye = {0.f, 0.6f, 2.5f};  // below the emitter, which it sees from the front
  s.camera.target = {0.f, 0.f, 0.f};
  s.camera.up = {0.f, 1.f, 0.f};
  s.camera.fovYDeg = 60.f;
  return s;
}

double PlaneUnderLight::radiance(const Camera& camera, const float3& d, int* surface) {
  *surface = -1;
  const float3 o = camera.eye;
  if (d[1] > 0.f && o[1] < kHeight) {  // up toward the emitter's plane, from below it
    const float3 x = o + d * ((kHeight - o[1]) / d[1]);
    if (std::fabs(x[0]) <= kLightHalf && std::fabs(x[2]) <= kLightHalf) {
      *surface = 1;
      return kLe;
    }
    return 0.0;
  }
  if (d[1] < 0.f && o[1] > 0.f) {  // down toward the plane
    const float3 x = o + d * (-o[1] / d[1]);
    if (std::fabs(x[0]) > kPlaneHalf || std::fabs(x[2]) > kPlaneHalf) return 0.0;
    *surface = 0;
    return kRho / M_PI * lambertIrradiance(x, {0, 1, 0}, light(), kLe);
  }
  return 0.0;
}

namespace {
constexpr double kPlastic = 1.32471795724474602596;  // x^3 = x + 1
constexpr double kR2x = 1.0 / kPlastic, kR2y = 1.0 / (kPlastic * kPlastic);
}  // namespace

Image PlaneUnderLight::reference(const Camera& camera, int width, int height, int sub, bool markEdges) {
  const CameraFrame f = makeCameraFrame(camera, width, height);
  // The mean radiance over n points of pixel (x, y); *mixed: they saw different surfaces.
  // R2 points (Roberts' plastic-number lattice), not a grid: a sub x sub grid has only `sub`
  // distinct heights, so a horizontal edge (the light's) would be off by up to 1/(2 sub) of
  // a pixel in every pixel of its row alike.
  auto pixelMean = [&](int x, int y, int n, bool* mixed) {
    double sum = 0;
    int first = -2;
    *mixed = false;
    for (int k = 0; k < n; ++k) {
      const double u = std::fmod(0.5 + k * kR2x, 1.0), v = std::fmod(0.5 + k * kR2y, 1.0);
      int surface;
      const float3 d = normalize(cameraRayDirection(f, float(x + u), float(y + v), width, height));
      sum += radiance(camera, d, &surface);
      *mixed |= first != -2 && surface != first;
      first = surface;
    }
    return sum / n;
  };
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.resize(size_t(width) * size_t(height) * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      bool mixed;
      double mean = pixelMean(x, y, sub * sub, &mixed);
      // Edge pixels are the only hard part of the integral: 64 times the points there.
      if (mixed && !markEdges) mean = pixelMean(x, y, 64 * sub * sub, &mixed);
      const float v = markEdges && mixed ? NAN : float(mean);
      for (int c = 0; c < 3; ++c) img.rgb[size_t(3 * (y * width + x) + c)] = v;
    }
  return img;
}

bool isBuiltinSpec(const std::string& spec) { return spec.rfind("builtin:", 0) == 0; }

Scene builtinScene(const std::string& spec) {
  if (spec == "builtin:plane-under-light") return PlaneUnderLight::scene();
  throw Error("'" + spec + "': unknown built-in scene (use builtin:plane-under-light)");
}

Image builtinReference(const std::string& spec, int width, int height) {
  const Scene s = builtinScene(spec);
  return PlaneUnderLight::reference(s.camera, width, height, 16, false);
}

}  // namespace fh
