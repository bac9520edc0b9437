// Ray casting over arrays of rays stored as float4 pairs (origin.xyz + tmin, direction.xyz +
// tmax): closest hit and any hit, for fredholm bench and the tests (accel/ray_caster.cpp).
#include "intersect.h"

// hits[i]: the closest hit as stored_hit packs it (intersect.h).
__kernel void intersect_closest(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                __global const float4* ray_org, __global const float4* ray_dir,
                                __global float4* hits, uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const float4 o = ray_org[i], d = ray_dir[i];
  hits[i] = stored_hit(trace_ray(nodes, blocks, o.xyz, d.xyz, o.w, d.w, false));
}

// occluded[i] = 1 if anything lies on the segment [tmin, tmax), else 0.
__kernel void intersect_any(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                            __global const float4* ray_org, __global const float4* ray_dir,
                            __global int* occluded, uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const float4 o = ray_org[i], d = ray_dir[i];
  occluded[i] = trace_ray(nodes, blocks, o.xyz, d.xyz, o.w, d.w, true).triangle >= 0;
}
