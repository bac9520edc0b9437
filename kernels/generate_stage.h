// The generate stage: camera rays. generate starts the samples plan_iteration planned in
// free path slots and queues them for intersection (the wavefront's refill), FH_LANES
// samples per work-item (lanes.h).
// The stage's functions; kernels/generate.cl holds its kernel, and the megakernel calls them.
#ifndef FH_GENERATE_STAGE_H
#define FH_GENERATE_STAGE_H

#include "camera.h"
#include "film.h"
#include "path_state.h"
#include "sampler.h"

// Starts device sample j (a device numbers its samples locally, mod 2^32) in path slot
// `slot`. Its passes are granted by the host, which may hand different passes to different
// devices: from a shape's first sample on, every shape.pixels samples are one local pass,
// whose global pass and first entry in the pass buffers are in pass_table at its pass slot,
// and sample i of a pass renders the shape's i-th pixel (types.h) into the entry i after its
// pass's (pass_entry, with the slot), around the ring of `entries`. Samples before
// newer.first_sample are of the older shape; local numbers wrap, so samples are compared by
// their distance from the older shape's first (the host starts a new shape before one
// spans 2^31 samples). The sample is point pass + offset of its pixel's sequence (the
// listed pixel's offset, two list halves on: host/render/pass_source.h), and the pixel and
// its point seed the random numbers, so a sample is the same whichever device renders it,
// and no sample number of the render (point * pixels + pixel) is formed that could
// overflow.
FH_INLINE void start_sample(RenderParams params, PassShape older, PassShape newer, uint entries, luint j, luint slot,
                            lmask active, __global const float* filter_table, __global const uint* pass_table,
                            __global const uint* pixel_list FH_PATH_PARAMS) {
  const lmask is_newer = j - older.first_sample >= (luint)(newer.first_sample - older.first_sample);
  const luint pixels = select((luint)(older.pixels), (luint)(newer.pixels), is_newer);
  const luint in_shape = j - select((luint)(older.first_sample), (luint)(newer.first_sample), is_newer);
  const luint local_pass = select((luint)(older.first_pass), (luint)(newer.first_pass), is_newer) + in_shape / pixels;
  const luint pass_slot = local_pass % FH_MAX_PASS_SLOTS;
  const luint index = in_shape % pixels;
  // A shape of every pixel lists none (FH_EVERY_PIXEL): its i-th pixel is pixel i, at offset 0.
  const luint list = select((luint)(older.list), (luint)(newer.list), is_newer);
  const lmask listed = list != FH_EVERY_PIXEL;
  luint pixel = index, offset = (luint)(0);
  if (lanes_any(listed)) {
    pixel = select(index, gather_uint(pixel_list, select((luint)(0), list + index, listed)), listed);
    offset = select(offset, gather_uint(pixel_list, select((luint)(0), list + index + 2u * params.pixel_count, listed)),
                    listed);
  }
  const luint point = gather_uint(pass_table, 2u * pass_slot) + offset;
  const luint entry = (gather_uint(pass_table, 2u * pass_slot + 1u) + index) % entries;
  const PixelSampler sampler = pixel_sampler_at(params.seed, point, pixel, params.replicates);
  const lvec2 u = sample_2d(&sampler, (luint)(FH_DIM_PIXEL));
  const uint width = (uint)params.camera.width;
  const lfloat px = lconvert_float(pixel % width) + 0.5f + filter_offset(filter_table, params.filter_table_size, u.x);
  const lfloat py = lconvert_float(pixel / width) + 0.5f + filter_offset(filter_table, params.filter_table_size, u.y);
  scatter_xyzw(ray_org, slot, v3_uniform(vload3(0, params.camera.origin)), (lfloat)(0.0f), active);
  scatter_xyzw(ray_dir, slot, camera_ray_direction(&params.camera, px, py), (lfloat)(INFINITY), active);
  scatter_xyzw(throughput, slot, v3_splat(1.0f), (lfloat)(0.0f), active);
  scatter_float(ray_pdf, slot, (lfloat)(0.0f), active);
  scatter_xyzw(radiance, slot, v3_splat(0.0f), (lfloat)(0.0f), active);
  // Kept, not recomputed at every bounce from the sample's index (divisions and hashes).
  scatter_uint(pixel_seed, slot, sampler.pixel_seed, active);
  scatter_uint(point_reversed, slot, sampler.index_reversed, active);
  scatter_uint(pass_entry, slot, FH_PASS_ENTRY(entry, pass_slot), active);
  scatter_uint(depth, slot, (luint)(0), active);
}

#endif
