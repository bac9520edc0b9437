// The rays of a work-item's lanes, set up for traversal together: with FH_LANES 8, the
// per-ray constants of all eight (divisions included) in vector lanes, then each lane's
// ray traversed on its own (a traversal's branches differ too much between rays to share
// lanes), or for coherent rays all eight as a packet. The same constants, bit for bit, as
// precompute_ray gives each ray alone.
#ifndef FH_LANE_RAYS_H
#define FH_LANE_RAYS_H

#include "intersect_packet.h"
#include "lanes.h"

#if FH_LANES == 8
typedef RayPrecomp8 LaneRays;
FH_INLINE void precompute_lane_rays(lvec3 org, lvec3 dir, LaneRays* rays) {
  precompute_rays8(org.x, org.y, org.z, dir.x, dir.y, dir.z, rays);
}
FH_INLINE RayPrecomp lane_ray(const LaneRays* rays, int l) { return ray_of_lane(rays, l); }

// The eight rays as one packet (intersect_packet.h), for rays that go together (the camera
// rays of neighbouring pixels). Lanes left out carry an active lane's ray, so their
// arithmetic stays finite.
FH_INLINE void make_lane_packet(lvec3 org, lvec3 dir, lfloat t_min, lmask active, RayPacket* packet) {
  const int first = lowest_bit(lane_bits(active));
  const lvec3 o = v3_select(active, org, v3_uniform(v3_lane(org, first)));
  const lvec3 d = v3_select(active, dir, v3_uniform(v3_lane(dir, first)));
  make_packet_lanes(o.x, o.y, o.z, d.x, d.y, d.z, select((lfloat)(LANE(t_min, first)), t_min, active), packet);
}
#else
typedef RayPrecomp LaneRays;
FH_INLINE void precompute_lane_rays(lvec3 org, lvec3 dir, LaneRays* rays) {
  *rays = precompute_ray(v3_lane(org, 0), v3_lane(dir, 0));
}
FH_INLINE RayPrecomp lane_ray(const LaneRays* rays, int l) { return *rays; }
#endif

// The closest hit of each lane's ray where `active`, within [t_min, t_max], lane by lane
// (their constants set up together); triangle -1 where there is none, or the lane is not
// active.
typedef struct {
  lint triangle;
  lfloat t, b1, b2;
} LaneHit;

FH_INLINE LaneHit closest_hits(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, lvec3 org,
                               lvec3 dir, lfloat t_min, lfloat t_max, lmask active) {
  LaneRays rays;
  precompute_lane_rays(org, dir, &rays);
  LaneHit h;
  h.triangle = (lint)(-1);
  h.t = h.b1 = h.b2 = (lfloat)(0.0f);
  const luint lanes = lane_positions(0);
  for (uint left = lanes_bits(active); left != 0u; left &= left - 1u) {
    const int l = lowest_bit(left);
    const TraceHit one = trace_precomputed(nodes, blocks, lane_ray(&rays, l), LANE(t_min, l), LANE(t_max, l));
    // Put together in registers: a lane written in memory and read back as a vector waits
    // for the store.
    const lmask here = lanes == (luint)(l);
    h.triangle = select(h.triangle, (lint)(one.triangle), here);
    h.t = select(h.t, (lfloat)(one.t), here);
    h.b1 = select(h.b1, (lfloat)(one.b1), here);
    h.b2 = select(h.b2, (lfloat)(one.b2), here);
  }
  return h;
}

#endif
