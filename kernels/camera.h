// The pinhole camera: a ray through image position (px, py) in pixels, (0,0) at the
// top-left corner; right = forward x up (see host/scene/camera.h). Lane-wise (lanes.h).
#ifndef FH_CAMERA_H
#define FH_CAMERA_H

#include "lanes.h"

FH_INLINE lvec3 camera_ray_direction(const CameraParams* cam, lfloat px, lfloat py) {
  const lfloat sx = 2.0f * px / (float)cam->width - 1.0f;
  const lfloat sy = 1.0f - 2.0f * py / (float)cam->height;
  const lvec3 f = v3_uniform(vload3(0, cam->forward)), r = v3_uniform(vload3(0, cam->right)),
              u = v3_uniform(vload3(0, cam->up));
  return v3_normalize(v3_add(v3_add(f, v3_scale(r, sx)), v3_scale(u, sy)));
}

#endif
