// Spawning rays from surfaces without self-intersection: the hit point is rebuilt from
// barycentrics (its error then scales with the triangle's coordinates, not with the
// ray's length) and pushed off the surface along the geometric normal by an amount that
// scales with the magnitude of the point and of the triangle, in the spirit of Wachter
// and Binder ("A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
// Gems ch. 6). Their fixed 1/32 near-origin threshold assumes scenes of unit scale; this
// offset is scale-invariant, so it holds for scenes scaled by 1e-3 or 1e4 and for
// geometry far from the origin.
#ifndef FH_RAY_H
#define FH_RAY_H

#include "types.h"

// 2^-16 of the magnitude: ~128 ulps of the largest coordinate, well above the error of
// the interpolated point and of the watertight test's sheared coordinates.
#define FH_OFFSET_SCALE (1.0f / 65536.0f)

FH_INLINE float max_component(float3 v) { return fmax(fmax(v.x, v.y), v.z); }

typedef struct {
  float3 position;
  float3 normal;     // geometric, unit length, on the front (counter-clockwise) side
  float magnitude;   // largest |coordinate| of the triangle's vertices and the point
} SurfacePoint;

FH_INLINE SurfacePoint surface_point(__global const float4* triangles, int t, float b1, float b2) {
  const float3 v0 = triangles[3 * t].xyz, v1 = triangles[3 * t + 1].xyz, v2 = triangles[3 * t + 2].xyz;
  SurfacePoint s;
  s.position = (1.0f - b1 - b2) * v0 + b1 * v1 + b2 * v2;
  s.normal = normalize(cross(v1 - v0, v2 - v0));
  s.magnitude = max_component(fmax(fmax(fabs(v0), fabs(v1)), fmax(fabs(v2), fabs(s.position))));
  return s;
}

// The origin for a ray leaving the surface on the side `side` (any vector on that side).
FH_INLINE float3 offset_ray_origin(const SurfacePoint* s, float3 side) {
  const float3 n = dot(s->normal, side) >= 0.0f ? s->normal : -s->normal;
  return s->position + n * (FH_OFFSET_SCALE * s->magnitude);
}

// Shadow rays stop this fraction short of their target, itself offset off the light.
#define FH_SHADOW_SHORTEN (1.0f - 1.0f / 1048576.0f)

#endif
