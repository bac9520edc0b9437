// The generate stage's kernel: one launch over its queue (functions: generate_stage.h).
#include "generate_stage.h"

// Starts the planned samples in the slots on top of the free list and appends them to
// the ray queue.
__kernel void generate(RenderParams params, __global const WavefrontCounters* counters,
                       __global const uint* free_list, __global uint* ray_queue, __global const float* filter_table,
                       __global const uint* pass_table, __global const uint* pixel_list FH_PATH_PARAMS) {
  const luint position = lane_positions(get_global_id(0) * FH_LANES);
  const lmask active = position < counters->new_count;
  if (!lanes_any(active)) return;
  const luint i = select((luint)(0), position, active);  // idle lanes compute sample 0 and write nothing
  const luint slot = gather_uint(free_list, counters->new_free_top - 1 - i);
  start_sample(params, counters->shapes[0], counters->shapes[1], counters->pass_entries, counters->new_first + i, slot,
               active, filter_table, pass_table, pixel_list FH_PATH_ARGS);
  scatter_uint(ray_queue, counters->new_queue_base + i, slot, active);
}
