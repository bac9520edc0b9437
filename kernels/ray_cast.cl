// Ray casting over arrays of rays stored as float4 pairs (origin.xyz + tmin, direction.xyz +
// tmax): closest hit and any hit, for fredholm bench and the tests (accel/ray_caster.cpp).
// The *_packets kernels trace eight consecutive rays per work-item together, for coherent
// batches; the *_lanes and *_streams kernels take eight or FH_STREAM consecutive rays per
// work-item too, but set them up together (the divisions in vector lanes) and trace them one
// by one or as a stream. All find the same hits, bit for bit.
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

// The x, y, z and w components of the eight float4 at p, each as a vector, from two
// vector loads and their shuffles (where eight scalar stores read back as a vector would
// wait for the stores to retire).
#define FH_COLUMNS8(p, x, y, z, w)                                             \
  do {                                                                         \
    const float16 first_ = vload16(0, (p)), second_ = vload16(1, (p));         \
    x = shuffle2(first_, second_, (uint8)(0, 4, 8, 12, 16, 20, 24, 28));       \
    y = shuffle2(first_, second_, (uint8)(1, 5, 9, 13, 17, 21, 25, 29));       \
    z = shuffle2(first_, second_, (uint8)(2, 6, 10, 14, 18, 22, 26, 30));      \
    w = shuffle2(first_, second_, (uint8)(3, 7, 11, 15, 19, 23, 27, 31));      \
  } while (0)

// Rays [first, first + 8) of the batch (those before ray_count): their constants in lanes,
// set up together by ray_constants8, and their segments. Lanes past the batch repeat its
// last ray. Returns how many are in the batch.
FH_INLINE int load_ray_lanes8(__global const float4* ray_org, __global const float4* ray_dir, uint first,
                              uint ray_count, RayLanes8* lanes, float8* t_min, float8* t_max) {
  const int count = (int)min(ray_count - first, 8u);
  float8 ox, oy, oz, dx, dy, dz;
  if (count == 8) {
    FH_COLUMNS8((__global const float*)(ray_org + first), ox, oy, oz, *t_min);
    FH_COLUMNS8((__global const float*)(ray_dir + first), dx, dy, dz, *t_max);
  } else {
    float c[8][8];  // the eight components, ray l's at index l
    for (int l = 0; l < 8; ++l) {
      const float4 o = ray_org[first + (uint)min(l, count - 1)], d = ray_dir[first + (uint)min(l, count - 1)];
      c[0][l] = o.x;
      c[1][l] = o.y;
      c[2][l] = o.z;
      c[3][l] = o.w;
      c[4][l] = d.x;
      c[5][l] = d.y;
      c[6][l] = d.z;
      c[7][l] = d.w;
    }
    ox = vload8(0, c[0]);
    oy = vload8(0, c[1]);
    oz = vload8(0, c[2]);
    *t_min = vload8(0, c[3]);
    dx = vload8(0, c[4]);
    dy = vload8(0, c[5]);
    dz = vload8(0, c[6]);
    *t_max = vload8(0, c[7]);
  }
  *lanes = ray_constants8(ox, oy, oz, dx, dy, dz);
  return count;
}

// As intersect_closest, eight consecutive rays per work-item, set up together and then
// traced one by one (incoherent rays part ways at once: lane_rays.h).
__kernel void intersect_closest_lanes(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                      __global const float4* ray_org, __global const float4* ray_dir,
                                      __global float4* hits, uint ray_count) {
  const uint first = get_global_id(0) * 8;
  if (first >= ray_count) return;
  RayLanes8 lanes;
  float8 t_min8, t_max8;
  const int count = load_ray_lanes8(ray_org, ray_dir, first, ray_count, &lanes, &t_min8, &t_max8);
  RayPrecomp8 r;
  store_rays8(&r, lanes);
  float t_min[8], t_max[8];
  vstore8(t_min8, 0, t_min);
  vstore8(t_max8, 0, t_max);
  _Pragma("unroll 1") for (int l = 0; l < count; ++l) {
    hits[first + l] = stored_hit(trace_precomputed(nodes, blocks, ray_of_lane(&r, l), t_min[l], t_max[l]));
  }
}

// As intersect_any, FH_STREAM consecutive rays per work-item, traced together as a stream.
__kernel void intersect_any_streams(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                    __global const float4* ray_org, __global const float4* ray_dir,
                                    __global int* occluded, uint ray_count) {
  const uint first = get_global_id(0) * FH_STREAM;
  if (first >= ray_count) return;
  const int count = (int)min(ray_count - first, (uint)FH_STREAM);
  RayStream stream;
  for (int g = 0; g < count; g += 8) {
    RayLanes8 lanes;
    float8 t_min, t_max;
    load_ray_lanes8(ray_org, ray_dir, first + (uint)g, ray_count, &lanes, &t_min, &t_max);
    add_rays8(&stream, g, lanes, t_min, t_max);
  }
  const ulong hit = find_occluders(nodes, blocks, &stream, count);
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
