// The scene in one device's memory: the BVH (through RayCaster), per-triangle materials
// in BVH order, the materials as the kernels see them, and the light-sampling tables.
#pragma once
#include <vector>

#include "bvh.h"
#include "ray_caster.h"
#include "scene.h"

namespace fh {

// Emissive triangles chosen in proportion to power: light i is BVH-order triangle
// triangle[i], picked with probability cdf[i] - cdf[i-1]. pdfArea[t] is, per BVH-order
// triangle, P(pick t) / area(t) (zero for non-emitters), the density light sampling
// gives each point of t, which mis needs when BSDF sampling hits an emitter.
struct LightTable {
  std::vector<float> cdf;
  std::vector<int> triangle;
  std::vector<float> pdfArea;
};

LightTable buildLightTable(const Scene& scene, const Bvh& bvh);

std::vector<gpu::GpuMaterial> toGpuMaterials(const Scene& scene);

class DeviceScene {
 public:
  DeviceScene(DeviceContext& dc, const Scene& scene, const Bvh& bvh);

  RayCaster caster;
  unsigned lightCount = 0;
  cl::Buffer triangleMaterial, materials, lightCdf, lightTriangle, lightPdfArea;
};

}  // namespace fh
