// Sampling routines shared by the stages: orthonormal bases, cosine-weighted hemisphere
// directions and uniform points on triangles.
#ifndef FH_SAMPLING_H
#define FH_SAMPLING_H

// A right-handed basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal
// Basis, Revisited", JCGT 2017).
inline void orthonormal_basis(float3 n, float3* t, float3* b) {
  const float sign = copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  *t = (float3)(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = (float3)(c, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about unit n from (u1, u2) in [0,1)^2; pdf = cos / pi.
inline float3 sample_cosine_hemisphere(float3 n, float u1, float u2) {
  const float r = sqrt(u1), phi = 2.0f * M_PI_F * u2;
  float3 t, b;
  orthonormal_basis(n, &t, &b);
  return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(fmax(0.0f, 1.0f - u1)) * n);
}

// Barycentrics (b1, b2) of a uniform point on a triangle.
inline float2 sample_triangle(float u1, float u2) {
  const float su = sqrt(u1);
  return (float2)(su * u2, 1.0f - su);
}

#endif
