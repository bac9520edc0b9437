// The rays of a work-item's lanes, set up for traversal together: with FH_LANES 8, the
// per-ray constants of all eight (divisions included) in vector lanes, then each lane's
// ray traversed on its own (a traversal's branches differ too much between rays to share
// lanes). The same constants, bit for bit, as precompute_ray gives each ray alone.
#ifndef FH_LANE_RAYS_H
#define FH_LANE_RAYS_H

#include "intersect.h"
#include "lanes.h"

#if FH_LANES == 8
typedef RayPrecomp8 LaneRays;
FH_INLINE void precompute_lane_rays(lvec3 org, lvec3 dir, LaneRays* rays) {
  precompute_rays8(org.x, org.y, org.z, dir.x, dir.y, dir.z, rays);
}
FH_INLINE RayPrecomp lane_ray(const LaneRays* rays, int l) { return ray_of_lane(rays, l); }
#else
typedef RayPrecomp LaneRays;
FH_INLINE void precompute_lane_rays(lvec3 org, lvec3 dir, LaneRays* rays) {
  *rays = precompute_ray(v3_lane(org, 0), v3_lane(dir, 0));
}
FH_INLINE RayPrecomp lane_ray(const LaneRays* rays, int l) { return *rays; }
#endif

#endif
