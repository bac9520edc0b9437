// The accumulate stage: finished paths hand their radiance to their pass's buffer (one
// sample per pixel per pass, so one writer per entry) and free their slots. The host reads
// a pass back once all its pixels are in and merges passes into the film in pass order,
// which keeps the image deterministic for a seed whatever order paths finish in. Up to
// FH_MAX_PASS_SLOTS passes are in flight, so the wavefront stays full while a pass's
// last, longest paths finish. FH_LANES paths per work-item (lanes.h).
#include "path_state.h"
#include "lanes.h"

// Writes the radiance of finished paths p (where `active`) to their entries in the pass
// buffers, a non-finite value as zero; returns which were finite and sets *pass_slot to
// their pass slots.
FH_INLINE lmask record_samples(luint p, lmask active, __global float4* pass_buffer, luint* pass_slot FH_PATH_PARAMS) {
  const luint code = gather_uint(pass_entry, p);
  lvec3 value = gather_xyz(radiance, p);
  const lmask finite = isfinite(value.x) && isfinite(value.y) && isfinite(value.z);
  value = v3_select(finite, value, v3_splat(0.0f));
  scatter_xyzw(pass_buffer, FH_PASS_ENTRY_INDEX(code), value, (lfloat)(1.0f), active);
  *pass_slot = FH_PASS_ENTRY_SLOT(code);
  return finite;
}

#if !defined(FH_MEGAKERNEL)  // the megakernel calls the stage function itself
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
#endif
