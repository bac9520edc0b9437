// Small float3 helpers for host code (std::array<float, 3>).
#pragma once
#include <array>
#include <cmath>
#include <cstdlib>

namespace fh {

using float3 = std::array<float, 3>;

inline float3 operator+(const float3& a, const float3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline float3 operator-(const float3& a, const float3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline float3 operator*(const float3& a, float s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline float dot(const float3& a, const float3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline float3 cross(const float3& a, const float3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline float length(const float3& a) { return std::sqrt(dot(a, a)); }
inline float3 normalize(const float3& a) { return a * (1.f / length(a)); }
inline bool isFinite(const float3& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }
inline float3 minv(const float3& a, const float3& b) {
  return {std::fmin(a[0], b[0]), std::fmin(a[1], b[1]), std::fmin(a[2], b[2])};
}
inline float3 maxv(const float3& a, const float3& b) {
  return {std::fmax(a[0], b[0]), std::fmax(a[1], b[1]), std::fmax(a[2], b[2])};
}

// The exponent of the power of two (an exact scaling) that brings `magnitude` into [1, 2),
// or 0 where its own exponent is within `band` of zero already, or it is zero or not finite:
// how scenes far from unit size or brightness are brought near it (Scene::worldScale,
// render/radiance_unit.h).
inline int exponentTowardOne(double magnitude, int band) {
  if (!(magnitude > 0.0) || !std::isfinite(magnitude)) return 0;
  const int exponent = std::ilogb(magnitude);
  return std::abs(exponent) <= band ? 0 : -exponent;
}

}  // namespace fh
