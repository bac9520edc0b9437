// Debug rendering (--aov): albedo, geometric normal or depth of the first hit, through
// the generate and intersect kernels, before any light transport.
#pragma once
#include <string>

#include "bvh.h"
#include "camera.h"
#include "image_io.h"
#include "ray_caster.h"
#include "scene.h"

namespace fh {

enum class Aov { Albedo = 0, Normal = 1, Depth = 2 };

// Throws fh::Error naming --aov for an unknown name.
Aov parseAov(const std::string& name);

struct AovSettings {
  int width = 512, height = 512;
  int spp = 4;  // jittered samples per pixel, box filter
  unsigned seed = 1;
  Aov mode = Aov::Albedo;
};

ProgramSpec aovProgram();

gpu::CameraParams makeCameraParams(const Camera& camera, int width, int height);

Image renderAov(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera, const AovSettings& s);

}  // namespace fh
