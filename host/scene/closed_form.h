// Scenes with a known answer, built in code: their exact images are the references of the
// tests and of the convergence charts (`fredholm render builtin:NAME`, `fredholm
// reference builtin:NAME`).
#pragma once
#include <string>
#include <vector>

#include "base/vec.h"
#include "image/image_io.h"
#include "scene/scene.h"

namespace fh {

// Irradiance at x (normal n) from a uniformly emitting polygon of radiance le, wholly in
// front of x: E = (le / 2) |sum_k Theta_k (n . Gamma_k)| (Lambert's polygon formula).
double lambertIrradiance(const float3& x, const float3& n, const std::vector<float3>& polygon, double le);

// A diffuse plane (y = 0, 10 x 10, albedo 0.5) under a one-sided 1 x 1 emitter of radiance
// 4 at height 1 facing it; nothing else. Its camera sees the plane and the emitter's front.
struct PlaneUnderLight {
  static constexpr float kRho = 0.5f, kLe = 4.f, kHeight = 1.f, kLightHalf = 0.5f, kPlaneHalf = 5.f;
  static Scene scene();  // with its camera
  static std::vector<float3> light();
  // Radiance along the camera ray through direction d; *surface: -1 none, 0 plane, 1 light.
  static double radiance(const Camera& camera, const float3& d, int* surface);
  // The exact image (box filter: each pixel the mean of sub^2 well-spread points). With
  // markEdges, pixels whose footprint sees more than one surface are NaN.
  static Image reference(const Camera& camera, int width, int height, int sub, bool markEdges);
};

// "builtin:plane-under-light" -> the scene; throws fh::Error for an unknown name.
Scene builtinScene(const std::string& spec);
bool isBuiltinSpec(const std::string& spec);
Image builtinReference(const std::string& spec, int width, int height);

}  // namespace fh
