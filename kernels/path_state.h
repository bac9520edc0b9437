// The path state, declared once: each field is one structure-of-arrays buffer indexed by
// path slot. The host (host/path_tracer.cpp) expands the same list to allocate the
// buffers and bind them, in this order, to every stage's FH_PATH_PARAMS.
#ifndef FH_PATH_STATE_H
#define FH_PATH_STATE_H

#include "types.h"

// X(type, name, bytes per path): what it holds
#define FH_PATH_FIELDS(X)                                                                         \
  X(float4, ray_org, 16)        /* origin xyz, tmin */                                           \
  X(float4, ray_dir, 16)        /* unit direction xyz, tmax */                                   \
  X(float4, hit, 16)            /* t, b1, b2, triangle (BVH order) bits or -1 */                 \
  X(float4, throughput, 16)     /* rgb; w: pdf of the BSDF sample that made ray_dir (for MIS) */ \
  X(float4, radiance, 16)       /* rgb gathered so far */                                        \
  X(uint, sample_id, 4)         /* global sample index: pixel = id % pixels, pass = id / pixels */ \
  X(uint, local_pass, 4)        /* this device's pass number for the sample: its pass buffer */    \
  X(uint, depth, 4)             /* bounces so far */

// The light-sample requests shade hands to shadow_connect, stored by queue position (so
// they are written and read in order), one buffer per field like the path state.
#define FH_SHADOW_FIELDS(X)                                                                   \
  X(uint, shadow_path, 4)           /* the path slot the contribution goes to */             \
  X(float4, shadow_position, 16)    /* shading point, w: its magnitude (for ray offsets) */  \
  X(float4, shadow_normal, 16)      /* shading normal on the viewer's side, w: material */   \
  X(float4, shadow_geometric, 16)   /* geometric normal on the viewer's side */              \
  X(float4, shadow_albedo, 16)      /* diffuse albedo there (textures) */                    \
  X(float4, shadow_throughput, 16)  /* throughput before the BSDF sample, w: bounce count */ \
  X(float4, shadow_wo, 16)          /* direction toward the previous vertex */

// The random dimensions of one bounce, shared by shade and shadow_connect so no two uses
// of one sample's numbers overlap: dimension = bounce * FH_DIMS_PER_BOUNCE + FH_DIM_*.
// The pixel sampler (sampler.h) draws U1/U2 pairs together as one 2D point.
#define FH_DIMS_PER_BOUNCE 8
#define FH_DIM_BSDF_U1 0
#define FH_DIM_BSDF_U2 1
#define FH_DIM_ROULETTE 2
#define FH_DIM_LIGHT_PICK 3
#define FH_DIM_LIGHT_U1 4
#define FH_DIM_LIGHT_U2 5
#define FH_DIM_BSDF_LOBE 6
// The sub-pixel position (two dimensions), far above every bounce's.
#define FH_DIM_PIXEL 0x7fff0000u

#ifdef __OPENCL_VERSION__
#define FH_PATH_PARAM(type, name, bytes) , __global type* name
// Appended to a kernel's parameter list: `__kernel void k(int a FH_PATH_PARAMS)`.
#define FH_PATH_PARAMS FH_PATH_FIELDS(FH_PATH_PARAM)
#define FH_SHADOW_PARAMS FH_SHADOW_FIELDS(FH_PATH_PARAM)
#endif

// Device-side counters, one uint each, in one buffer. The device keeps its own books
// (plan_iteration and finish_iteration), so the host can queue many iterations without
// waiting for any: it reads the counters back only now and then.
#define FH_COUNT_RAYS_A 0         // ray queue A length
#define FH_COUNT_RAYS_B 1         // ray queue B length
#define FH_COUNT_SHADOW 2         // light-sample requests this iteration
#define FH_COUNT_FINISHED 3       // paths finished this iteration
#define FH_COUNT_NONFINITE 4      // samples whose radiance was NaN or infinite (dropped)
#define FH_COUNT_FREE 5           // free path slots: the free list's length
#define FH_COUNT_NEXT_SAMPLE 6    // samples started so far on this device (local numbering)
#define FH_COUNT_SAMPLE_LIMIT 7   // local samples that may start: the passes granted so far
#define FH_COUNT_GEN_COUNT 8      // this iteration's new samples
#define FH_COUNT_GEN_FIRST 9      // ... the first one's index
#define FH_COUNT_GEN_FREE_TOP 10  // ... the free list's length before they took their slots
#define FH_COUNT_GEN_QUEUE_BASE 11 // ... where they go in the ray queue
#define FH_COUNT_BOUNCE_RAYS 12   // 64-bit totals as (low, high) pairs: bounce rays,
#define FH_COUNT_SHADOW_RAYS 14   // shadow rays,
#define FH_COUNT_QUEUED_RAYS 16   // and rays queued per iteration (for occupancy)
#define FH_COUNT_ITERATIONS 18    // iterations run
#define FH_MAX_PASS_SLOTS 8       // passes in flight at most (the host picks FH_PASS_SLOTS <= this)
#ifndef FH_PASS_SLOTS
#define FH_PASS_SLOTS FH_MAX_PASS_SLOTS  // pass p uses pass-buffer slot p % FH_PASS_SLOTS
#endif
#define FH_COUNT_PASS_DONE 19     // one counter per slot: paths finished in the pass it holds
#define FH_COUNT_TOTAL (FH_COUNT_PASS_DONE + FH_MAX_PASS_SLOTS)

#ifdef __OPENCL_VERSION__
// Appends to a queue with one global atomic per work-group rather than per item: the
// items of a group count themselves in local memory first. Two CPU threads incrementing
// one global counter per item bounce its cache line between cores, which cost as much as
// the rest of shade. Every work-item of the group must call it (it has barriers); it
// returns the item's position in the queue, or 0xFFFFFFFF if it appends nothing.
FH_INLINE uint group_append(bool append, volatile __global uint* counter, volatile __local uint* scratch) {
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[0] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint local_index = append ? atomic_inc(&scratch[0]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) scratch[1] = scratch[0] ? atomic_add(counter, scratch[0]) : 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  return append ? scratch[1] + local_index : 0xFFFFFFFFu;
}
#endif

#endif
