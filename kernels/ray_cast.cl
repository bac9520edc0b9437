// Ray casting over arrays of rays stored as float4 pairs (origin.xyz + tmin, direction.xyz +
// tmax): closest hit and any hit, for fredholm bench and the tests (accel/ray_caster.cpp).
// The *_packets kernels trace eight consecutive rays per work-item together, for coherent
// batches; they find the same hits.
#include "intersect_packet.h"
#include "intersect_stream.h"

// hits[i]: the closest hit as stored_hit packs it (intersect.h).
__kernel void intersect_closest(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                __global const float4* ray_org, __global const float4* ray_dir,
                                __global float4* hits, uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const float4 o = ray_org[i], d = ray_dir[i];
  hits[i] = stored_hit(trace_ray(nodes, blocks, o.xyz, d.xyz, o.w, d.w));
}

// occluded[i] = 1 if anything lies on the segment [tmin, tmax), else 0.
__kernel void intersect_any(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                            __global const float4* ray_org, __global const float4* ray_dir,
                            __global int* occluded, uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const float4 o = ray_org[i], d = ray_dir[i];
  occluded[i] = find_occluder(nodes, blocks, o.xyz, d.xyz, o.w, d.w) >= 0;
}

// As intersect_any, FH_STREAM consecutive rays per work-item, traced together as a stream.
__kernel void intersect_any_streams(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                    __global const float4* ray_org, __global const float4* ray_dir,
                                    __global int* occluded, uint ray_count) {
  const uint first = get_global_id(0) * FH_STREAM;
  if (first >= ray_count) return;
  const int count = (int)min(ray_count - first, (uint)FH_STREAM);
  RayPrecomp r[FH_STREAM];
  float t_min[FH_STREAM], t_max[FH_STREAM];
  for (int l = 0; l < count; ++l) {
    const float4 o = ray_org[first + l], d = ray_dir[first + l];
    r[l] = precompute_ray(o.xyz, d.xyz);
    t_min[l] = o.w;
    t_max[l] = d.w;
  }
  const ulong hit = find_occluders(nodes, blocks, r, t_min, t_max, count);
  for (int l = 0; l < count; ++l) occluded[first + l] = (int)((hit >> l) & 1ul);
}

// Rays [8 i, 8 i + 8) of the batch as a packet.
FH_INLINE int trace_packet_of(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                              __global const float4* ray_org, __global const float4* ray_dir, uint ray_count,
                              bool any_hit, TraceHit* hit) {
  const uint first = get_global_id(0) * FH_PACKET;
  if (first >= ray_count) return 0;
  const int count = (int)min(ray_count - first, (uint)FH_PACKET);
  float3 org[FH_PACKET], dir[FH_PACKET];
  float t_min[FH_PACKET], t_max[FH_PACKET];
  for (int l = 0; l < count; ++l) {
    const float4 o = ray_org[first + l], d = ray_dir[first + l];
    org[l] = o.xyz;
    dir[l] = d.xyz;
    t_min[l] = o.w;
    t_max[l] = d.w;
  }
  trace_packet(nodes, blocks, org, dir, t_min, t_max, count, any_hit, hit);
  return count;
}

// As intersect_closest, eight rays per work-item.
__kernel void intersect_closest_packets(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                        __global const float4* ray_org, __global const float4* ray_dir,
                                        __global float4* hits, uint ray_count) {
  TraceHit hit[FH_PACKET];
  const int count = trace_packet_of(nodes, blocks, ray_org, ray_dir, ray_count, false, hit);
  for (int l = 0; l < count; ++l) hits[get_global_id(0) * FH_PACKET + l] = stored_hit(hit[l]);
}

// As intersect_any, eight rays per work-item.
__kernel void intersect_any_packets(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                    __global const float4* ray_org, __global const float4* ray_dir,
                                    __global int* occluded, uint ray_count) {
  TraceHit hit[FH_PACKET];
  const int count = trace_packet_of(nodes, blocks, ray_org, ray_dir, ray_count, true, hit);
  for (int l = 0; l < count; ++l) occluded[get_global_id(0) * FH_PACKET + l] = hit[l].triangle >= 0;
}
