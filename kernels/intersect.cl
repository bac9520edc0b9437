// The intersect stage's kernel: one launch over its queue (functions: intersect_stage.h).
#include "intersect_stage.h"

// The intersect stage: closest hit for the paths in the current ray queue (parity picks
// its length).
__kernel void intersect(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                        __global const uint* ray_queue, __global const WavefrontCounters* counters, uint parity,
                        __global const float4* ray_org, __global const float4* ray_dir, __global float4* hit) {
  const uint i = get_global_id(0);
  if (i >= counters->ray_length[parity]) return;
  intersect_slot(nodes, blocks, ray_queue[i], ray_org, ray_dir, hit);
}
