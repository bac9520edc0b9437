// Queues of path slots on the device: an array of slot indices and its length, which
// lives in the WavefrontCounters (types.h). The host's side of the same queues is
// host/render/wavefront.h.
#ifndef FH_QUEUES_H
#define FH_QUEUES_H

#include "lanes.h"

// Appends each lane's `slot` to `queue` where `append` is set, in lane order, with one
// global atomic per work-group rather than per item: the work-items of a group count
// their lanes in local memory first. Two CPU threads incrementing one global counter per
// item bounce its cache line between cores, which cost as much as the rest of shade. Every
// work-item of the group must call it (it has barriers); it returns each lane's position
// in the queue, or 0xFFFFFFFF where it appends nothing (callers that store more than the
// slot use the position).
FH_INLINE luint queue_append(lmask append, luint slot, __global uint* queue, volatile __global uint* length,
                             volatile __local uint* scratch) {
  uint count = 0;
  FH_FOR_LANES(l) count += LANE(append, l) ? 1u : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[0] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint local_first = count ? atomic_add(&scratch[0], count) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[1] = scratch[0] ? atomic_add(length, scratch[0]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  luint position = (luint)(0xFFFFFFFFu);
  uint next = scratch[1] + local_first;
  FH_FOR_LANES(l) {
    if (!LANE(append, l)) continue;
    queue[next] = LANE(slot, l);
    LANE(position, l) = next++;
  }
  return position;
}

#endif
