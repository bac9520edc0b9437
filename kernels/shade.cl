// The shade stage's kernel: one launch over its queue (functions: shade_stage.h).
#include "shade_stage.h"

__kernel void shade(RenderParams params, __global const uint* ray_queue, __global uint* next_queue,
                    __global uint* finished_queue, volatile __global WavefrontCounters* counters,
                    uint parity FH_SCENE_PARAMS, __global float4* aovs FH_PATH_PARAMS FH_SHADOW_PARAMS) {
  const SceneView scene = FH_SCENE_VIEW;
  volatile __local uint scratch[2 * 3];
  const luint position = lane_positions(get_global_id(0) * FH_LANES);
  const lmask active = position < counters->ray_length[parity];
  // Idle lanes (past the queue's end) read the work-item's first path, which no other
  // work-item writes, and write nothing.
  const luint p =
      lanes_any(active) ? gather_uint(ray_queue, select((luint)(LANE(position, 0)), position, active)) : (luint)(0);
  const ShadeOutcome o = shade_paths(params, p, active, &scene, aovs FH_PATH_ARGS);

  // Continuing paths to the next ray queue, light-sample requests to shadow_connect's,
  // finished paths to accumulate's.
  const lmask append[3] = {o.continues, o.light_sample, o.finished};
  __global uint* const queues[3] = {next_queue, shadow_path, finished_queue};
  volatile __global uint* const lengths[3] = {&counters->ray_length[1 - parity], &counters->shadow_length,
                                              &counters->finished_length};
  luint positions[3];
  queue_append_each(3, append, p, queues, lengths, scratch, positions);
  if (lanes_any(o.light_sample)) store_shadow_request(&o.request, positions[1], o.light_sample FH_SHADOW_ARGS);
}
