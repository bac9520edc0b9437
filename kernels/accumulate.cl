// The accumulate stage: finished paths hand their radiance to the film. A path writes to
// the buffer of its pass (one sample per pixel per pass, so one writer per pixel) and
// frees its slot; a completed pass is then added to the film's sums in pass order, which
// keeps the image deterministic for a given seed whatever order paths finish in. Up to
// FH_PASS_SLOTS passes are in flight, so the wavefront stays full while a pass's last,
// longest paths finish.
#include "path_state.h"

__kernel void accumulate_paths(__global const uint* finished_queue, volatile __global uint* counters,
                               __global uint* free_list, uint pixel_count, __global float4* pass_buffer FH_PATH_PARAMS) {
  volatile __local uint finished_in_slot[FH_PASS_SLOTS];
  const uint i = get_global_id(0), lid = get_local_id(0);
  if (lid < FH_PASS_SLOTS) finished_in_slot[lid] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (i < counters[FH_COUNT_FINISHED]) {
    const uint p = finished_queue[i];
    const uint pixel = sample_id[p] % pixel_count, slot = local_pass[p] % FH_PASS_SLOTS;
    float3 value = radiance[p].xyz;
    if (!all(isfinite(value))) {
      // Counted and reported (stats: nonfinite_samples); the tests require zero.
      atomic_inc(&counters[FH_COUNT_NONFINITE]);
      value = (float3)(0.0f);
    }
    pass_buffer[slot * pixel_count + pixel] = (float4)(value, 1.0f);
    atomic_inc(&finished_in_slot[slot]);
    free_list[counters[FH_COUNT_FREE] + i] = p;
  }
  // One global atomic per pass slot and work-group (see group_append).
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < FH_PASS_SLOTS && finished_in_slot[lid]) atomic_add(&counters[FH_COUNT_PASS_DONE + lid], finished_in_slot[lid]);
}

// Closes an iteration's books (a single work-item): the freed slots join the free list,
// and the ray totals grow.
FH_INLINE void add_64(volatile __global uint* pair, uint value) {
  const uint low = pair[0] + value;
  pair[1] += low < value;  // carry
  pair[0] = low;
}

__kernel void finish_iteration(volatile __global uint* counters, uint ray_counter, uint next_counter) {
  if (get_global_id(0) != 0) return;
  counters[FH_COUNT_FREE] += counters[FH_COUNT_FINISHED];
  add_64(counters + FH_COUNT_BOUNCE_RAYS, counters[next_counter]);
  add_64(counters + FH_COUNT_SHADOW_RAYS, counters[FH_COUNT_SHADOW]);
  add_64(counters + FH_COUNT_QUEUED_RAYS, counters[ray_counter]);
  counters[FH_COUNT_ITERATIONS] += 1;
}

// Adds pass `pass`'s buffer to the film: per pixel the sum of samples (w: count) and the
// sum of their squares, from which the variance of the pixel estimate follows.
__kernel void accumulate_pass(__global float4* pass_buffer, uint pass, uint pixel_count, __global float4* film_sum,
                              __global float4* film_sum_sq) {
  const uint pixel = get_global_id(0);
  if (pixel >= pixel_count) return;
  __global float4* slot = pass_buffer + (pass % FH_PASS_SLOTS) * pixel_count + pixel;
  const float4 v = *slot;
  film_sum[pixel] += v;
  film_sum_sq[pixel] += (float4)(v.xyz * v.xyz, 0.0f);
  *slot = (float4)(0.0f);
}
