// Light sampling for next-event estimation: an emissive triangle chosen in proportion
// to its power (a CDF over the light list), then a point on it: uniform in the solid angle
// it subtends where that is well conditioned (Arvo 1995), else uniform in area (the area
// formulation: Le f G V / p_area, with p_area = P(triangle) / area). Solid-angle sampling
// bounds the estimate where area sampling's 1/r^2 is unbounded: a light next to the
// receiver, e.g. across a concave edge of an emitting room, where area sampling's variance
// is infinite.
#ifndef FH_LIGHTS_H
#define FH_LIGHTS_H

#include "sampling.h"
#include "types.h"

// The first light whose CDF value exceeds u (binary search).
FH_INLINE uint pick_light(__global const float* cdf, uint count, float u) {
  uint lo = 0, hi = count - 1;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2;
    if (cdf[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

// Converts an area density at a point seen at distance^2 `dist2` under cosine `cos_light`
// to a solid-angle density at the receiver.
FH_INLINE float area_to_solid_angle(float pdf_area, float dist2, float cos_light) {
  return cos_light > 0.0f ? pdf_area * dist2 / cos_light : 0.0f;
}

// A triangle as seen from a point: unit directions to its corners and its solid angle
// (Van Oosterom and Strackee 1983).
typedef struct {
  float3 a, b, c;
  float solid_angle;
} SphericalTriangle;

FH_INLINE SphericalTriangle spherical_triangle(float3 o, float3 v0, float3 v1, float3 v2) {
  SphericalTriangle t;
  t.a = normalize(v0 - o);
  t.b = normalize(v1 - o);
  t.c = normalize(v2 - o);
  const float triple = fabs(dot(t.a, cross(t.b, t.c)));
  t.solid_angle = 2.0f * atan2(triple, 1.0f + dot(t.a, t.b) + dot(t.b, t.c) + dot(t.c, t.a));
  return t;
}

// The triangle as light sampling sees it from o: by solid angle (solid_angle > 0) when it
// is large for its distance (area above a quarter of the squared distance to its centroid),
// where area sampling's 1/r^2 makes the estimate spiky, and the spherical triangle is
// neither so small that its angles lose precision in float nor nearly a hemisphere
// (pbrt-v4's bounds); by area (solid_angle 0) otherwise, which costs less and is about as
// good for small or distant lights. Light samples and the MIS weights of BSDF-found
// emission both decide by this.
FH_INLINE SphericalTriangle light_seen_from(float3 o, float3 v0, float3 v1, float3 v2, float area) {
  const float3 to_centroid = (v0 + v1 + v2) * (1.0f / 3.0f) - o;
  if (area <= 0.25f * dot(to_centroid, to_centroid)) {
    SphericalTriangle by_area;
    by_area.a = by_area.b = by_area.c = (float3)(0.0f);
    by_area.solid_angle = 0.0f;
    return by_area;
  }
  SphericalTriangle t = spherical_triangle(o, v0, v1, v2);
  if (!(t.solid_angle > 3e-4f && t.solid_angle < 6.22f)) t.solid_angle = 0.0f;
  return t;
}

FH_INLINE float3 normalize_or(float3 v, float3 fallback) {
  const float len2 = dot(v, v);
  return len2 > 0.0f ? v * rsqrt(len2) : fallback;
}

// A direction uniform in the spherical triangle (Arvo, "Stratified sampling of spherical
// triangles", 1995): u1 picks the sub-triangle with area u1 * solid angle, which fixes its
// third corner on the arc a-c; u2 picks a point on the arc from b to that corner.
FH_INLINE float3 sample_spherical_triangle(const SphericalTriangle* t, float u1, float u2) {
  const float3 a = t->a, b = t->b, c = t->c;
  // The angle at corner a between the great circles a-b and a-c.
  const float3 n_ab = normalize_or(cross(a, b), (float3)(0.0f)), n_ac = normalize_or(cross(a, c), (float3)(0.0f));
  const float cos_alpha = clamp(dot(n_ab, n_ac), -1.0f, 1.0f), sin_alpha = sqrt(fmax(0.0f, 1.0f - cos_alpha * cos_alpha));
  // sin and cos of (u1 * solid angle - alpha), by the angle-difference identities.
  const float2 sc = sincos_reduced(u1 * t->solid_angle);
  const float s = sc.x * cos_alpha - sc.y * sin_alpha, tt = sc.y * cos_alpha + sc.x * sin_alpha;
  const float u = tt - cos_alpha, v = s + sin_alpha * dot(a, b);
  const float denominator = (v * s + u * tt) * sin_alpha;
  const float q = denominator != 0.0f ? clamp(((v * tt - u * s) * cos_alpha - v) / denominator, -1.0f, 1.0f) : 1.0f;
  const float3 c_hat = q * a + sqrt(fmax(0.0f, 1.0f - q * q)) * normalize_or(c - dot(c, a) * a, c);
  const float z = 1.0f - u2 * (1.0f - dot(c_hat, b));
  return normalize(z * b + sqrt(fmax(0.0f, 1.0f - z * z)) * normalize_or(c_hat - dot(c_hat, b) * b, c_hat));
}

// Barycentrics (b1, b2) of the point where the ray o + s w meets the plane of the triangle
// (Moller-Trumbore), clamped into the triangle: a direction drawn inside the spherical
// triangle hits it up to rounding.
FH_INLINE float2 barycentrics_along(float3 o, float3 w, float3 v0, float3 v1, float3 v2) {
  const float3 e1 = v1 - v0, e2 = v2 - v0, p = cross(w, e2), d = o - v0, q = cross(d, e1);
  const float inv = 1.0f / dot(e1, p);
  float b1 = clamp(dot(d, p) * inv, 0.0f, 1.0f), b2 = clamp(dot(w, q) * inv, 0.0f, 1.0f);
  const float excess = b1 + b2 - 1.0f;
  if (excess > 0.0f) {
    b1 -= 0.5f * excess;
    b2 -= 0.5f * excess;
  }
  return (float2)(b1, b2);
}

// A light triangle as light sampling treats it from a receiver's ray origin: its corners,
// area, the chance `pick` that light sampling chooses it, and how it is sampled from there
// (seen.solid_angle > 0: by solid angle). shadow_connect samples with it and shade weighs
// BSDF-found emission with it, so both use one density (light_pdf) for the same point.
typedef struct {
  float3 v0, v1, v2;
  float area, pick;
  SphericalTriangle seen;
} LightTriangle;

FH_INLINE LightTriangle light_triangle_from(__global const float4* triangles, int t, float pdf_area, float3 origin) {
  LightTriangle l;
  l.v0 = triangles[3 * t].xyz;
  l.v1 = triangles[3 * t + 1].xyz;
  l.v2 = triangles[3 * t + 2].xyz;
  l.area = 0.5f * length(cross(l.v1 - l.v0, l.v2 - l.v0));
  l.pick = pdf_area * l.area;  // pdf_area = P(triangle) / area
  l.seen = light_seen_from(origin, l.v0, l.v1, l.v2, l.area);
  return l;
}

// The density (per solid angle at the receiver) with which light sampling picks a point of
// light triangle l at squared distance dist2, seen under cos_light.
FH_INLINE float light_pdf(const LightTriangle* l, float dist2, float cos_light) {
  if (l->seen.solid_angle > 0.0f) return l->pick / l->seen.solid_angle;
  return area_to_solid_angle(l->pick / l->area, dist2, cos_light);
}

// The power heuristic (beta = 2) weight of a sample drawn with density `a` against `b`.
FH_INLINE float power_heuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

#endif
