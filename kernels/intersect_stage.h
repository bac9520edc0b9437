// The path tracer's intersect stage: the closest hit of each path's ray (ray casting over
// plain arrays of rays, for the bench and the tests, is ray_cast.cl).
// The stage's functions; kernels/intersect.cl holds its kernel, and the megakernel calls them.
#ifndef FH_INTERSECT_STAGE_H
#define FH_INTERSECT_STAGE_H

#include "lane_rays.h"
#include "path_state.h"

// Closest hit for the ray of path slot p: reads ray_org/ray_dir, writes hit.
FH_INLINE void intersect_slot(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, uint p,
                              __global const float4* ray_org, __global const float4* ray_dir, __global float4* hit) {
  const float4 o = ray_org[p], d = ray_dir[p];
  hit[p] = stored_hit(trace_ray(nodes, blocks, o.xyz, d.xyz, o.w, d.w));
}

// Closest hits for the rays of the lanes' path slots p where `active` (the megakernel's
// eight paths): intersect_slot for each, their rays set up together.
FH_INLINE void intersect_lanes(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, luint p,
                               lmask active, FH_PATH_SPACE const FH_PATH_TYPE(float4)* ray_org,
                               FH_PATH_SPACE const FH_PATH_TYPE(float4)* ray_dir,
                               FH_PATH_SPACE FH_PATH_TYPE(float4)* hit) {
  lfloat t_min, t_max;
  const lvec3 org = gather_xyzw(ray_org, p, &t_min), dir = gather_xyzw(ray_dir, p, &t_max);
  const LaneHit h = closest_hits(nodes, blocks, org, dir, t_min, t_max, active);
  // As stored_hit stores each.
  const lfloat t = select(h.t, (lfloat)(INFINITY), h.triangle < 0);
  scatter_xyzw(hit, p, v3(t, h.b1, h.b2), las_float(h.triangle), active);
}

// intersect_lanes for the camera rays of samples that start together (the megakernel's
// lanes, neighbouring pixels): they take nearly the same path through the tree, and one
// traversal serves all eight (intersect_packet.h: the same hits, bit for bit).
FH_INLINE void intersect_camera_lanes(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, luint p,
                                      lmask active, FH_PATH_SPACE const FH_PATH_TYPE(float4)* ray_org,
                                      FH_PATH_SPACE const FH_PATH_TYPE(float4)* ray_dir,
                                      FH_PATH_SPACE FH_PATH_TYPE(float4)* hit) {
#if FH_LANES == 8
  lfloat t_min, t_max;
  const lvec3 org = gather_xyzw(ray_org, p, &t_min), dir = gather_xyzw(ray_dir, p, &t_max);
  RayPacket packet;
  make_lane_packet(org, dir, t_min, active, &packet);
  const PacketHits h = trace_packet_lanes(nodes, blocks, &packet, select((lfloat)(-INFINITY), t_max, active), false);
  // As stored_hit stores each.
  const lfloat t = select(h.t, (lfloat)(INFINITY), h.triangle < 0);
  scatter_xyzw(hit, p, v3(t, h.b1, h.b2), as_float8(h.triangle), active);
#else
  intersect_lanes(nodes, blocks, p, active, ray_org, ray_dir, hit);
#endif
}

#endif
