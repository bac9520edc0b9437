// The accumulate stage: finished paths hand their radiance to their pass's buffer (one
// sample per pixel per pass, so one writer per pixel) and free their slots. The host reads
// a pass back once all its pixels are in and merges passes into the film in pass order,
// which keeps the image deterministic for a seed whatever order paths finish in. Up to
// FH_PASS_SLOTS passes are in flight, so the wavefront stays full while a pass's last,
// longest paths finish.
#include "path_state.h"

__kernel void accumulate(__global const uint* finished_queue, volatile __global WavefrontCounters* counters,
                         __global uint* free_list, uint pixel_count, __global float4* pass_buffer FH_PATH_PARAMS) {
  volatile __local uint finished_in_slot[FH_PASS_SLOTS];
  const uint i = get_global_id(0), lid = get_local_id(0);
  if (lid < FH_PASS_SLOTS) finished_in_slot[lid] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (i < counters->finished_length) {
    const uint p = finished_queue[i];
    const uint pixel = sample_id[p] % pixel_count, slot = local_pass[p] % FH_PASS_SLOTS;
    float3 value = radiance[p].xyz;
    if (!all(isfinite(value))) {
      // Counted and reported (stats: nonfinite_samples); the tests require zero.
      atomic_inc(&counters->nonfinite);
      value = (float3)(0.0f);
    }
    pass_buffer[slot * pixel_count + pixel] = (float4)(value, 1.0f);
    atomic_inc(&finished_in_slot[slot]);
    free_list[counters->free_length + i] = p;
  }
  // One global atomic per pass slot and work-group (see queue_append).
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < FH_PASS_SLOTS && finished_in_slot[lid]) atomic_add(&counters->pass_done[lid], finished_in_slot[lid]);
}
