// Secondary rays from a batch of closest hits, appended to an output queue with an atomic
// counter: cosine-weighted bounce rays (incoherent) and shadow rays to uniform points on
// emissive triangles. Used by `fredholm bench` and the ray-casting tests; the path
// tracer's stages spawn their rays with the same ray.h and sampling.h (one lane here).
#include "ray.h"
#include "rng.h"
#include "sampling.h"

// Appends one ray per hit (misses are skipped); source[k] = index of the hit it came from.
__kernel void spawn_bounce_rays(__global const float4* hits, __global const float4* in_dir,
                                __global const float4* triangles, uint seed, __global float4* out_org,
                                __global float4* out_dir, __global uint* source, volatile __global uint* count,
                                uint hit_count) {
  const uint i = get_global_id(0);
  if (i >= hit_count) return;
  const float4 h = hits[i];
  const int t = as_int(h.w);
  if (t < 0) return;
  const SurfacePoint s = surface_point(triangles, t, h.y, h.z);
  // Leave on the side the ray arrived from.
  const lvec3 toward = v3_uniform(-in_dir[i].xyz);
  const lvec3 n = v3_select(v3_dot(s.normal, toward) >= 0.0f, s.normal, v3_neg(s.normal));
  const lvec3 d = sample_cosine_hemisphere(n, random_float(seed, i, 0), random_float(seed, i, 1));
  const uint k = atomic_inc(count);
  out_org[k] = (float4)(v3_lane(offset_ray_origin(&s, toward), 0), 0.0f);
  out_dir[k] = (float4)(v3_lane(d, 0), INFINITY);
  source[k] = i;
}

// Appends one shadow ray per hit toward a uniform point on a random emissive triangle
// (indices in BVH order); the segment stops just short of the offset light point.
__kernel void spawn_shadow_rays(__global const float4* hits, __global const float4* in_dir,
                                __global const float4* triangles, __global const int* lights, uint light_count,
                                uint seed, __global float4* out_org, __global float4* out_dir,
                                __global uint* source, volatile __global uint* count, uint hit_count) {
  const uint i = get_global_id(0);
  if (i >= hit_count || light_count == 0) return;
  const float4 h = hits[i];
  const int t = as_int(h.w);
  if (t < 0) return;
  const SurfacePoint s = surface_point(triangles, t, h.y, h.z);
  const uint pick = min((uint)(random_float(seed, i, 2) * (float)light_count), light_count - 1);
  const lvec2 b = sample_triangle(random_float(seed, i, 3), random_float(seed, i, 4));
  const SurfacePoint l = surface_point(triangles, lights[pick], b.x, b.y);
  // Only light on the viewer's side of an opaque surface is reflected, and emitters shine
  // from their front side only: the path tracer traces no ray for either case.
  const lvec3 to_light = v3_sub(l.position, s.position);
  const lvec3 viewer = v3_uniform(-in_dir[i].xyz);
  if (v3_dot(s.normal, to_light) * v3_dot(s.normal, viewer) <= 0.0f || v3_dot(l.normal, to_light) >= 0.0f) return;
  const float3 origin = v3_lane(offset_ray_origin(&s, viewer), 0);
  const float3 target = v3_lane(offset_ray_origin(&l, v3_neg(to_light)), 0);
  const float3 d = target - origin;
  const float dist = length(d);
  if (!(dist > 0.0f)) return;
  const uint k = atomic_inc(count);
  out_org[k] = (float4)(origin, 0.0f);
  out_dir[k] = (float4)(d / dist, dist * FH_SHADOW_SHORTEN);
  source[k] = i;
}
