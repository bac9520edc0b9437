// Sampling routines shared by the stages: orthonormal bases, cosine-weighted hemisphere
// directions and uniform points on triangles.
#ifndef FH_SAMPLING_H
#define FH_SAMPLING_H

#include "types.h"

// A right-handed basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017).
FH_INLINE void orthonormal_basis(float3 n, float3* t, float3* b) {
  const float sign = copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  *t = (float3)(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = (float3)(c, sign + n.y * n.y * a, -n.y);
}

// sin and cos on [-pi/4, pi/4] by their Taylor series to degree 9 and 8 (errors below
// 1e-8): PoCL's sin/cos take a third of the shade stage with their general argument
// reduction, and the concentric mapping needs no wider range.
FH_INLINE float2 sincos_quarter(float x) {
  const float x2 = x * x;
  const float s = x * (1.0f + x2 * (-1.0f / 6.0f + x2 * (1.0f / 120.0f + x2 * (-1.0f / 5040.0f + x2 / 362880.0f))));
  const float c = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24.0f + x2 * (-1.0f / 720.0f + x2 / 40320.0f)));
  return (float2)(s, c);
}

// sin and cos of any moderate angle: reduced by quarter turns to [-pi/4, pi/4].
FH_INLINE float2 sincos_reduced(float x) {
  const float k = rint(x * M_2_PI_F);
  const float2 sc = sincos_quarter(x - k * M_PI_2_F);
  switch (((int)k) & 3) {
    case 0: return sc;
    case 1: return (float2)(sc.y, -sc.x);
    case 2: return -sc;
    default: return (float2)(-sc.y, sc.x);
  }
}

// A uniform point on the unit disk from [0,1)^2 by Shirley and Chiu's concentric
// mapping (area-preserving, so stratified inputs stay stratified).
FH_INLINE float2 sample_concentric_disk(float u1, float u2) {
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) return (float2)(0.0f);
  if (fabs(a) > fabs(b)) {
    const float2 sc = sincos_quarter(M_PI_4_F * (b / a));
    return a * (float2)(sc.y, sc.x);
  }
  // phi = pi/2 - (pi/4)(a/b): cos(phi) = sin(theta), sin(phi) = cos(theta).
  const float2 sc = sincos_quarter(M_PI_4_F * (a / b));
  return b * (float2)(sc.x, sc.y);
}

// Cosine-weighted direction about unit n from (u1, u2) in [0,1)^2 (Malley's method: a
// uniform disk point lifted to the hemisphere); pdf = cos / pi.
FH_INLINE float3 sample_cosine_hemisphere(float3 n, float u1, float u2) {
  const float2 d = sample_concentric_disk(u1, u2);
  float3 t, b;
  orthonormal_basis(n, &t, &b);
  return normalize(d.x * t + d.y * b + sqrt(fmax(0.0f, 1.0f - dot(d, d))) * n);
}

// Barycentrics (b1, b2) of a uniform point on a triangle.
FH_INLINE float2 sample_triangle(float u1, float u2) {
  const float su = sqrt(u1);
  return (float2)(su * u2, 1.0f - su);
}

#endif
