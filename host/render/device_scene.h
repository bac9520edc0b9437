// The scene in one device's memory: the BVH (DeviceBvh), per-triangle materials
// in BVH order, the materials as the kernels see them, and the light-sampling tables.
#pragma once
#include <vector>

#include "accel/bvh.h"
#include "accel/ray_caster.h"
#include "scene/scene.h"

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

// The coarse features a scene uses; kernels are compiled with only these (-D flags), and
// buffers for the others are not allocated.
struct SceneFeatures {
  bool glossy = false;          // glossy or mirror lobes (illum 2/3/5/8 with Ks > 0)
  bool glass = false;           // dielectrics (illum 4/6/7/9)
  bool textures = false;        // map_Kd textures (with UVs)
  bool shadingNormals = false;  // vertex normals in the OBJ
  static SceneFeatures all() { return {true, true, true, true}; }
  std::string buildOptions() const;
  std::string describe() const;
};

SceneFeatures sceneFeatures(const Scene& scene);

// A texture as linear float RGBA texels (rows from the top), 8-bit images decoded from sRGB.
struct TextureData {
  int width = 0, height = 0;
  std::vector<float> texels;
};
// Reads a map_Kd image through OpenImageIO (1, 3 or 4 channels); throws fh::Error.
TextureData loadTexture(const std::string& path);

class DeviceScene {
 public:
  // `features` may include more than the scene uses (to measure specialization).
  DeviceScene(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const SceneFeatures& features);

  DeviceBvh bvh;
  SceneFeatures features;
  unsigned lightCount = 0;
  cl::Buffer triangleMaterial, materials, lightCdf, lightTriangle, lightPdfArea;
  cl::Buffer normals, uvs, texels, textureInfo;  // one-element placeholders when unused
  std::vector<std::string> warnings;             // textures that could not be read
};

}  // namespace fh
