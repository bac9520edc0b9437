// The wavefront's books, kept on the device so the host can queue many iterations
// without waiting for any: plan_iteration opens an iteration (how many new samples start,
// where they go), finish_iteration closes it (freed slots, ray totals). Each runs as a
// single work-item. `parity` says which of the two ray queues is current: an iteration
// reads one and fills the other.
#include "types.h"

__kernel void plan_iteration(volatile __global WavefrontCounters* counters, uint parity) {
  if (get_global_id(0) != 0) return;
  // Local sample numbers wrap (mod 2^32): the samples granted and not yet started are
  // limit - next, which the host keeps far below 2^32.
  const uint free_slots = counters->free_length, next = counters->next_sample, ready = counters->sample_limit - next;
#if defined(FH_MEGAKERNEL)
  // Every path a megakernel launch starts ends in it: no rays carry over, and the slots
  // are all free again (and stay in the free list) when it is done.
  const uint count = min(FH_MEGAKERNEL_SAMPLES_PER_SLOT * free_slots, ready);
  counters->ray_length[parity] = 0;
#else
  const uint count = min(free_slots, ready);
  counters->free_length = free_slots - count;
#endif
  counters->new_count = count;
  counters->new_first = next;
  counters->new_free_top = free_slots;
  counters->new_queue_base = counters->ray_length[parity];
  counters->next_sample = next + count;
  counters->ray_length[parity] += count;
  counters->ray_length[1 - parity] = 0;
  counters->shadow_length = 0;
  counters->finished_length = 0;
}

FH_INLINE void add_64(volatile __global uint* pair, uint value) {
  const uint low = pair[0] + value;
  pair[1] += low < value;  // carry
  pair[0] = low;
}

__kernel void finish_iteration(volatile __global WavefrontCounters* counters, uint parity) {
  if (get_global_id(0) != 0) return;
  counters->free_length += counters->finished_length;
  add_64(counters->bounce_rays, counters->ray_length[1 - parity]);
  add_64(counters->shadow_rays, counters->shadow_length);
  add_64(counters->queued_rays, counters->ray_length[parity]);
  counters->iterations += 1;
}
