// Spawning rays from surfaces without self-intersection: the hit point is rebuilt from
// barycentrics (its error then scales with the triangle's coordinates, not with the
// ray's length) and pushed off the surface along the geometric normal by an amount that
// scales with the magnitude of the point and of the triangle, in the spirit of Wachter
// and Binder ("A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
// Gems ch. 6). Their fixed 1/32 near-origin threshold assumes scenes of unit scale; this
// offset is scale-invariant, so it holds for scenes scaled by 1e-3 or 1e4 and for
// geometry far from the origin. Lane-wise (lanes.h).
#ifndef FH_RAY_H
#define FH_RAY_H

#include "lanes.h"

// 2^-16 of the magnitude: ~128 ulps of the largest coordinate, well above the error of
// the interpolated point and of the watertight test's sheared coordinates.
#define FH_OFFSET_SCALE (1.0f / 65536.0f)

typedef struct {
  lvec3 position;
  lvec3 normal;     // geometric, unit length, on the front (counter-clockwise) side
  lfloat magnitude; // largest |coordinate| of the triangle's vertices and the point
} SurfacePoint;

// Corner k (0, 1, 2) of triangles t.
FH_INLINE lvec3 triangle_corner(__global const float4* triangles, lint t, int k) {
  return gather_xyz(triangles, las_uint(3 * t + k));
}

// The point at barycentrics (b1, b2) of the triangle with corners v0, v1, v2.
FH_INLINE SurfacePoint surface_point_between(lvec3 v0, lvec3 v1, lvec3 v2, lfloat b1, lfloat b2) {
  SurfacePoint s;
  s.position = v3_add(v3_add(v3_scale(v0, 1.0f - b1 - b2), v3_scale(v1, b1)), v3_scale(v2, b2));
  s.normal = v3_normalize(v3_cross(v3_sub(v1, v0), v3_sub(v2, v0)));
  s.magnitude = v3_max_component(v3_max(v3_max(v3_abs(v0), v3_abs(v1)), v3_max(v3_abs(v2), v3_abs(s.position))));
  return s;
}

FH_INLINE SurfacePoint surface_point(__global const float4* triangles, lint t, lfloat b1, lfloat b2) {
  return surface_point_between(triangle_corner(triangles, t, 0), triangle_corner(triangles, t, 1),
                               triangle_corner(triangles, t, 2), b1, b2);
}

// The origin for a ray leaving the surface on the side `side` (any vector on that side).
FH_INLINE lvec3 offset_ray_origin(const SurfacePoint* s, lvec3 side) {
  const lvec3 n = v3_select(v3_dot(s->normal, side) >= 0.0f, s->normal, v3_neg(s->normal));
  return v3_madd(n, FH_OFFSET_SCALE * s->magnitude, s->position);
}

// Shadow rays stop this fraction short of their target, itself offset off the light.
#define FH_SHADOW_SHORTEN (1.0f - 1.0f / 1048576.0f)

#endif
