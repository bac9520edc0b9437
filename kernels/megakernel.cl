// The megakernel strategies: each work-item runs every stage for its FH_LANES path slots
// in one kernel, in a loop (no queues; a light-sample request goes straight to
// connect_light), and once all of its lanes' paths have ended, starts their next samples in
// the same slots (path regeneration, a work-item's lanes at a time). It calls
// the stages' own functions, so it computes the same estimator and the same image bits for
// a seed. Every path it starts ends in the same launch: plan_iteration (built with
// FH_MEGAKERNEL) carries no rays over, and the free list is left as it was.
#include "accumulate_stage.h"
#include "generate_stage.h"
#include "intersect_stage.h"
#include "shade_stage.h"
#include "shadow_connect_stage.h"

#ifdef FH_PRIVATE_PATHS
// The host binds the path state's buffers to every path-tracing program; this one keeps the
// state of its lanes in private arrays instead (below), and leaves the buffers alone.
#define FH_PATH_BUFFER(type, name, bytes) , __global type* name##_buffer
#define FH_PATH_BUFFERS FH_PATH_FIELDS(FH_PATH_BUFFER)
#define FH_PATH_PRIVATE(type, name, bytes) FH_PATH_TYPE(type) name[1];  // an array: passed as a pointer
#else
#define FH_PATH_BUFFERS FH_PATH_PARAMS
#endif

// Counts the finished lanes' samples in the work-group's books, per pass slot. The lanes
// start their samples together, so those that finish together mostly belong to one pass:
// then one atomic add counts them all.
FH_INLINE void count_finished(volatile __local uint* finished_in_slot, luint slot, lmask finished) {
  const luint low = select((luint)(UINT_MAX), slot, finished), high = select((luint)(0u), slot, finished);
  uint lowest = UINT_MAX, highest = 0u;
  FH_FOR_LANES(l) {
    lowest = min(lowest, LANE(low, l));
    highest = max(highest, LANE(high, l));
  }
  if (lowest == highest) {
    atomic_add(&finished_in_slot[lowest], lanes_count(finished));
    return;
  }
  FH_FOR_LANES(l) {
    if (LANE(finished, l)) atomic_inc(&finished_in_slot[LANE(slot, l)]);
  }
}

__kernel void megakernel(RenderParams params, volatile __global WavefrontCounters* counters, uint parity,
                         __global const uint* free_list, __global const float* filter_table,
                         __global const uint* pass_table, __global const uint* pixel_list FH_SCENE_PARAMS,
                         __global float4* pass_buffer, __global float4* aovs FH_PATH_BUFFERS) {
  const SceneView scene = FH_SCENE_VIEW;
  // The work-group's books, added to the device's once at the end (see queue_append_each):
  // samples finished per pass slot, then bounce rays, shadow rays and non-finite samples.
  volatile __local uint finished_in_slot[FH_MAX_PASS_SLOTS], totals[3];
  const uint lid = get_local_id(0);
  if (lid < FH_MAX_PASS_SLOTS) finished_in_slot[lid] = 0;
  if (lid < 3) totals[lid] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);

  // Lane g owns free slot g (all are free between launches) and takes samples g, g + slots,
  // g + 2 slots, ... of the new_count planned.
  const uint slots = counters->new_free_top, count = counters->new_count;
  const PassShape older = counters->shapes[0], newer = counters->shapes[1];
  const uint entries = counters->pass_entries;
  const luint g = lane_positions(get_global_id(0) * FH_LANES);
  const lmask owns_slot = g < slots && g < count;
  if (lanes_any(owns_slot)) {
#ifdef FH_PRIVATE_PATHS
    // The lanes' path state is the work-item's own, each field one set of vectors
    // (lanes.h), instead of global slots': no addresses computed from slot indices, no
    // transposes between a lane's float4 and the lanes' vectors, and the compiler can keep
    // the fields in registers.
    FH_PATH_FIELDS(FH_PATH_PRIVATE)
    const luint p = lane_positions(0);
#else
    const luint p = gather_uint(free_list, slots - 1 - select((luint)(0), g, owns_slot));
#endif
    luint next = g;  // the lane's next sample
    lmask alive = lanes_mask(false);
    uint bounce_rays = 0, shadow_rays = 0, nonfinite = 0;
    for (;;) {
      // The lanes start their next samples together, once all of the work-item's paths have
      // ended, not each as soon as its own ends: the lanes then follow neighbouring pixels at
      // the same depth, whose rays and materials take the same branches, and that pays more
      // than the lanes left idle cost (bench/RESULTS.md).
      if (!lanes_any(alive)) {
        alive = owns_slot && next < count;
        if (!lanes_any(alive)) break;
        start_sample(params, older, newer, entries, counters->new_first + next, p, alive, filter_table, pass_table,
                     pixel_list FH_PATH_ARGS);
        next = select(next, next + slots, alive);
        intersect_camera_lanes(scene.nodes, scene.blocks, p, alive, ray_org, ray_dir, hit);
      } else {
        intersect_lanes(scene.nodes, scene.blocks, p, alive, ray_org, ray_dir, hit);
      }
      const ShadeOutcome o = shade_paths(params, p, alive, &scene, aovs FH_PATH_ARGS);
      if (lanes_any(o.light_sample))  // never for pt, nor without lights
        connect_light(params, &o.request, &o.sampler, o.light_sample, &scene FH_PATH_ARGS);
      shadow_rays += lanes_count(o.light_sample);
      bounce_rays += lanes_count(o.continues);
      if (lanes_any(o.finished)) {
        luint slot;
        const lmask finite = record_samples(p, o.finished, pass_buffer, &slot FH_PATH_ARGS);
        count_finished(finished_in_slot, slot, o.finished);
        nonfinite += lanes_count(o.finished && !finite);
      }
      alive = o.continues;
    }
    if (bounce_rays) atomic_add(&totals[0], bounce_rays);
    if (shadow_rays) atomic_add(&totals[1], shadow_rays);
    if (nonfinite) atomic_add(&totals[2], nonfinite);
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < FH_MAX_PASS_SLOTS && finished_in_slot[lid]) atomic_add(&counters->pass_done[lid], finished_in_slot[lid]);
  if (lid == 0) {
    if (totals[0]) atomic_add(&counters->ray_length[1 - parity], totals[0]);
    if (totals[1]) atomic_add(&counters->shadow_length, totals[1]);
    if (totals[2]) atomic_add(&counters->nonfinite, totals[2]);
  }
}
