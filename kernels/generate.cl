// The generate stage: camera rays for a batch of (pixel, sample) pairs. Ray i of the
// batch is pixel (first_pixel + i) mod pixel_count; sub-pixel offsets are random per
// (seed, pixel, sample), a box pixel filter.
#include "camera.h"
#include "rng.h"

__kernel void generate_camera_rays(CameraParams cam, uint seed, uint sample_index, uint first_pixel,
                                   __global float4* ray_org, __global float4* ray_dir, __global uint* ray_pixel,
                                   uint ray_count) {
  const uint i = get_global_id(0);
  if (i >= ray_count) return;
  const uint pixel_count = (uint)(cam.width * cam.height);
  const uint pixel = (first_pixel + i) % pixel_count;
  const uint stream = hash_combine(pixel, sample_index);
  const float jx = random_float(seed, stream, 0), jy = random_float(seed, stream, 1);
  const float px = (float)(pixel % (uint)cam.width) + jx, py = (float)(pixel / (uint)cam.width) + jy;
  ray_org[i] = (float4)(vload3(0, cam.origin), 0.0f);
  ray_dir[i] = (float4)(camera_ray_direction(&cam, px, py), INFINITY);
  ray_pixel[i] = pixel;
}
