// The pinhole camera: a ray through image position (px, py) in pixels, (0,0) at the
// top-left corner; right = forward x up (see host/scene/camera.h).
#ifndef FH_CAMERA_H
#define FH_CAMERA_H

#include "types.h"

FH_INLINE float3 camera_ray_direction(const CameraParams* cam, float px, float py) {
  const float sx = 2.0f * px / (float)cam->width - 1.0f;
  const float sy = 1.0f - 2.0f * py / (float)cam->height;
  const float3 f = vload3(0, cam->forward), r = vload3(0, cam->right), u = vload3(0, cam->up);
  return normalize(f + sx * r + sy * u);
}

#endif
