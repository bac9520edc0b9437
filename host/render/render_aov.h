// Debug rendering (--aov): albedo, geometric normal or depth of the first hit, through
// the generate and intersect kernels, before any light transport.
#pragma once
#include <string>

#include "accel/bvh.h"
#include "accel/ray_caster.h"
#include "image/image_io.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

enum class Aov { Albedo = 0, Normal = 1, Depth = 2 };

struct AovSettings {
  int width = 512, height = 512;
  int spp = 4;  // jittered samples per pixel, box filter
  unsigned seed = 1;
  Aov mode = Aov::Albedo;
};

ProgramSpec aovProgram();

Image renderAov(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera, const AovSettings& s);

}  // namespace fh
