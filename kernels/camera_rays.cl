// One batch of jittered camera rays for the debug views and the ray-casting bench (the
// path tracer's own camera rays come from the generate stage).
#include "camera.h"
#include "rng.h"

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
  out_dir[i] = (float4)(v3_lane(camera_ray_direction(&cam, px, py), 0), INFINITY);
  out_pixel[i] = pixel;
}
