// Queues of path slots on the device: an array of slot indices and its length, which
// lives in the WavefrontCounters (types.h). The host's side of the same queues is
// host/render/wavefront.h.
#ifndef FH_QUEUES_H
#define FH_QUEUES_H

#include "types.h"

// Appends `slot` to `queue` when `append` is true, with one global atomic per work-group
// rather than per item: the items of a group count themselves in local memory first. Two
// CPU threads incrementing one global counter per item bounce its cache line between
// cores, which cost as much as the rest of shade. Every work-item of the group must call
// it (it has barriers); it returns the item's position in the queue, or 0xFFFFFFFF if it
// appends nothing (callers that store more than the slot use the position).
FH_INLINE uint queue_append(bool append, uint slot, __global uint* queue, volatile __global uint* length,
                            volatile __local uint* scratch) {
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[0] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint local_index = append ? atomic_inc(&scratch[0]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[1] = scratch[0] ? atomic_add(length, scratch[0]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (!append) return 0xFFFFFFFFu;
  const uint position = scratch[1] + local_index;
  queue[position] = slot;
  return position;
}

#endif
