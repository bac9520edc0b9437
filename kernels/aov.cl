// A debug shading stage: writes one arbitrary output variable (albedo, geometric normal
// or depth) of the first hit into the film, to see the scene through the device before
// any light transport. One ray per pixel per pass, so each pixel has one writer.
#include "types.h"

#define FH_AOV_ALBEDO 0
#define FH_AOV_NORMAL 1
#define FH_AOV_DEPTH 2

FH_INLINE float3 geometric_normal(__global const float4* triangles, int t) {
  const float3 v0 = triangles[3 * t].xyz, v1 = triangles[3 * t + 1].xyz, v2 = triangles[3 * t + 2].xyz;
  return normalize(cross(v1 - v0, v2 - v0));
}

__kernel void shade_aov(int mode, __global const float4* hits, __global const uint* ray_pixel,
                        __global const float4* triangles, __global const int* triangle_material,
                        __global const float4* material_albedo, __global float4* film, uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const float4 hit = hits[i];
  const int t = as_int(hit.w);
  float3 value = (float3)(0.0f);
  if (t >= 0) {
    if (mode == FH_AOV_ALBEDO) value = material_albedo[triangle_material[t]].xyz;
    else if (mode == FH_AOV_NORMAL) value = 0.5f * geometric_normal(triangles, t) + 0.5f;
    else value = (float3)(hit.x);
  }
  film[ray_pixel[i]] += (float4)(value, 1.0f);
}
