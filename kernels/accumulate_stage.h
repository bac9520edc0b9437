// The accumulate stage: finished paths hand their radiance to their pass's buffer (one
// sample per pixel per pass, so one writer per entry) and free their slots. The host reads
// a pass back once all its pixels are in and merges passes into the film in pass order,
// which keeps the image deterministic for a seed whatever order paths finish in. Up to
// FH_MAX_PASS_SLOTS passes are in flight, so the wavefront stays full while a pass's
// last, longest paths finish. FH_LANES paths per work-item (lanes.h).
// The stage's functions; kernels/accumulate.cl holds its kernel, and the megakernel calls them.
#ifndef FH_ACCUMULATE_STAGE_H
#define FH_ACCUMULATE_STAGE_H

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

#endif
