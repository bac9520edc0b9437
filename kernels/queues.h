// Queues of path slots on the device: an array of slot indices and its length, which
// lives in the WavefrontCounters (types.h). The host's side of the same queues is
// host/render/wavefront.h.
#ifndef FH_QUEUES_H
#define FH_QUEUES_H

#include "lanes.h"

#define FH_MAX_QUEUES_AT_ONCE 3

// Appends each lane's `slot` to queues[q] where append[q] is set, in lane order, for n
// queues at once, with one global atomic per queue and work-group rather than per item:
// the work-items of a group count their lanes in local memory first. Two CPU threads
// incrementing one global counter per item bounce its cache line between cores, which
// cost as much as the rest of shade. The n queues share one round of barriers, which CPU
// devices pay for (a work-group's work-items run in a loop between barriers, their live
// values stored and reloaded around each). Every work-item of the group must call it;
// scratch holds 2n entries. positions[q] gets each lane's position in queues[q], or
// 0xFFFFFFFF where it appends nothing (callers that store more than the slot use it).
FH_INLINE void queue_append_each(int n, const lmask* append, luint slot, __global uint* const* queues,
                                 volatile __global uint* const* lengths, volatile __local uint* scratch,
                                 luint* positions) {
  uint count[FH_MAX_QUEUES_AT_ONCE], first[FH_MAX_QUEUES_AT_ONCE];
  for (int q = 0; q < n; ++q) count[q] = lanes_count(append[q]);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0)
    for (int q = 0; q < n; ++q) scratch[q] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int q = 0; q < n; ++q) first[q] = count[q] ? atomic_add(&scratch[q], count[q]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0)
    for (int q = 0; q < n; ++q) scratch[n + q] = scratch[q] ? atomic_add(lengths[q], scratch[q]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int q = 0; q < n; ++q) {
    luint position = (luint)(0xFFFFFFFFu);
    uint next = scratch[n + q] + first[q];
    FH_FOR_LANES(l) {
      if (!LANE(append[q], l)) continue;
      queues[q][next] = LANE(slot, l);
      LANE(position, l) = next++;
    }
    positions[q] = position;
  }
}

#endif
