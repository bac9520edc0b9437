// The accumulate stage's kernel: one launch over its queue (functions: accumulate_stage.h).
#include "accumulate_stage.h"

__kernel void accumulate(__global const uint* finished_queue, volatile __global WavefrontCounters* counters,
                         __global uint* free_list, __global float4* pass_buffer FH_PATH_PARAMS) {
  volatile __local uint finished_in_slot[FH_MAX_PASS_SLOTS];
  const uint lid = get_local_id(0);
  if (lid < FH_MAX_PASS_SLOTS) finished_in_slot[lid] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  const luint position = lane_positions(get_global_id(0) * FH_LANES);
  const lmask active = position < counters->finished_length;
  if (lanes_any(active)) {
    const luint i = select((luint)(0), position, active);
    const luint p = gather_uint(finished_queue, i);
    luint slot;
    const lmask finite = record_samples(p, active, pass_buffer, &slot FH_PATH_ARGS);
    scatter_uint(free_list, counters->free_length + i, p, active);
    FH_FOR_LANES(l) {
      if (!LANE(active, l)) continue;
      atomic_inc(&finished_in_slot[LANE(slot, l)]);
      // Counted and reported (stats: nonfinite_samples); the tests require zero.
      if (!LANE(finite, l)) atomic_inc(&counters->nonfinite);
    }
  }
  // One global atomic per pass slot and work-group (see queue_append_each).
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < FH_MAX_PASS_SLOTS && finished_in_slot[lid]) atomic_add(&counters->pass_done[lid], finished_in_slot[lid]);
}
