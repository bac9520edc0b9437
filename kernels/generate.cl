// The generate stage: camera rays. generate starts the samples plan_iteration planned in
// free path slots and queues them for intersection (the wavefront's refill);
// generate_camera_rays makes one batch of camera rays for the debug views and the bench.
#include "camera.h"
#include "film.h"
#include "path_state.h"
#include "sampler.h"

// Starts the planned samples in the slots on top of the free list and appends them to
// the ray queue. A device numbers its samples locally (j); its passes are granted by the
// host, which may hand different passes to different devices: local pass j / pixel_count
// is global pass pass_table[j / pixel_count]. Global sample k = pass * pixel_count + pixel
// seeds the random numbers, so a sample is the same whichever device renders it.
__kernel void generate(RenderParams params, __global const WavefrontCounters* counters,
                       __global const uint* free_list, __global uint* ray_queue, __global const float* filter_table,
                       __global const uint* pass_table FH_PATH_PARAMS) {
  const uint i = get_global_id(0);
  if (i >= counters->new_count) return;
  const uint slot = free_list[counters->new_free_top - 1 - i];
  const uint j = counters->new_first + i;
  const uint pixel = j % params.pixel_count, device_pass = j / params.pixel_count;
  const uint pass = pass_table[device_pass];
  const uint k = pass * params.pixel_count + pixel;
  const PixelSampler sampler = pixel_sampler(params.seed, k, params.pixel_count);
  const float2 u = sample_2d(&sampler, FH_DIM_PIXEL);
  const float px = (float)(pixel % (uint)params.camera.width) + 0.5f +
                   filter_offset(filter_table, params.filter_table_size, u.x);
  const float py = (float)(pixel / (uint)params.camera.width) + 0.5f +
                   filter_offset(filter_table, params.filter_table_size, u.y);
  ray_org[slot] = (float4)(vload3(0, params.camera.origin), 0.0f);
  ray_dir[slot] = (float4)(camera_ray_direction(&params.camera, px, py), INFINITY);
  throughput[slot] = (float4)(1.0f, 1.0f, 1.0f, 0.0f);
  ray_pdf[slot] = 0.0f;
  radiance[slot] = (float4)(0.0f);
  sample_id[slot] = k;
  local_pass[slot] = device_pass;
  depth[slot] = 0;
  ray_queue[counters->new_queue_base + i] = slot;
}

__kernel void generate_camera_rays(CameraParams cam, uint seed, uint sample_index, uint first_pixel,
                                   __global float4* out_org, __global float4* out_dir, __global uint* out_pixel,
                                   uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const uint pixel_count = (uint)(cam.width * cam.height);
  const uint pixel = (first_pixel + i) % pixel_count;
  const uint stream = hash_combine(pixel, sample_index);
  const float jx = random_float(seed, stream, 0), jy = random_float(seed, stream, 1);
  const float px = (float)(pixel % (uint)cam.width) + jx, py = (float)(pixel / (uint)cam.width) + jy;
  out_org[i] = (float4)(vload3(0, cam.origin), 0.0f);
  out_dir[i] = (float4)(camera_ray_direction(&cam, px, py), INFINITY);
  out_pixel[i] = pixel;
}
