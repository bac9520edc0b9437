// The scene in one device's memory: the BVH (DeviceBvh), per-triangle materials
// in BVH order, the materials as the kernels see them, and the light-sampling tables.
#pragma once
#include <array>
#include <vector>

#include "accel/bvh.h"
#include "accel/ray_caster.h"
#include "kernels/scene_view.h"
#include "scene/environment_map.h"
#include "scene/scene.h"

namespace fh {

// Lights chosen by power: the environment map with probability environmentPick (its share
// of the power), else a triangle, half of those picks in proportion to power and half
// uniformly: emissive triangle i (BVH-order triangle triangle[i]) with
// probability cdf[i] - cdf[i-1] (cdf[-1] being environmentPick). pdfArea[t] is, per
// BVH-order triangle, P(pick t) / area(t) (zero for non-emitters), the density light
// sampling gives each point of t, which mis needs when BSDF sampling hits an emitter.
// The map's power is that of pbrt's infinite lights: the flux its radiance sends through
// a disk of the scene's bounding radius, pi r^2 times the luminance integrated over the
// sphere; a triangle's is pi area Ke (Light::power).
struct LightTable {
  std::vector<float> cdf;
  std::vector<int> triangle;
  std::vector<float> pdfArea;
  float environmentPick = 0.f;
  // The scene's bounding sphere (centre, radius: half the box's diagonal; zero for a scene
  // without triangles), whose disk the map's power goes through, and where bdpt's light
  // paths from the map start (kernels/bdpt.cl).
  std::array<float, 4> boundingSphere{};
};

LightTable buildLightTable(const Scene& scene, const Bvh& bvh, const EnvironmentMap* environment = nullptr);

std::vector<gpu::GpuMaterial> toGpuMaterials(const Scene& scene);

// The coarse features a scene uses; kernels are compiled with only these (-D flags), and
// buffers for the others are not allocated.
struct SceneFeatures {
  bool glossy = false;          // glossy or mirror lobes (illum 2/3/5/8 with Ks > 0)
  bool glass = false;           // dielectrics (illum 4/6/7/9)
  bool textures = false;        // map_Kd textures (with UVs)
  bool shadingNormals = false;  // vertex normals in the OBJ
  bool environmentMap = false;  // --env-map (a render setting rather than the OBJ's)
  static SceneFeatures all() { return {true, true, true, true, true}; }
  std::string buildOptions() const;
  std::string describe() const;
};

SceneFeatures sceneFeatures(const Scene& scene);

// Whether a material the scene uses has a delta lobe: glass, or a mirror (illum 3, 5 or 8
// with Ks > 0 and Ns at or past FH_NS_MIRROR, as kernels/bsdf.h decides).
bool hasDeltaLobes(const Scene& scene);

// A texture as the kernels read it (kernels/surface.h), rows from the top. An 8-bit image
// keeps its sRGB codes, a 32-bit word per texel (R | G << 8 | B << 16), for the kernels to
// decode through srgbDecodeTable(): a quarter of the memory of float texels, with the same
// values. Other images hold linear float RGBA, a word per channel (the float's bits).
struct TextureData {
  enum Format : uint32_t { kLinearFloat = FH_TEXELS_LINEAR_FLOAT, kSrgb8 = FH_TEXELS_SRGB8 };
  int width = 0, height = 0;
  Format format = kLinearFloat;
  std::vector<uint32_t> words;
  // Texels of a float image that no reflectance can be, as loadTexture mended them: not
  // finite (grey), negative (zero), above one (scaled down to one, hue kept, as Kd is).
  size_t notFinite = 0, negative = 0, aboveOne = 0;
};
// The linear value of each 8-bit sRGB code, as float bits: the first 256 words of the
// kernels' texel buffer.
std::vector<uint32_t> srgbDecodeTable();
// Reads a map_Kd image through OpenImageIO (1, 3 or 4 channels); throws fh::Error.
TextureData loadTexture(const std::string& path);

// The scene's buffers as the kernels take them, from the list kernels/scene_view.h declares
// once, in its order.
struct SceneBuffers {
#define FH_SCENE_BUFFER(type, name) cl::Buffer name;
  FH_SCENE_FIELDS(FH_SCENE_BUFFER)
#undef FH_SCENE_BUFFER
};

// The scene as every device holds it, prepared once on the host for all of them: the
// tables in BVH order, the materials as the kernels read them, the light table, the
// textures read and decoded, the environment map packed.
struct PreparedScene {
  SceneFeatures features;
  bool deltaLobes = false;  // hasDeltaLobes
  LightTable lights;
  std::vector<gpu::GpuMaterial> materials;
  std::vector<int> triangleMaterial;  // BVH order
  std::vector<float> cornerNormals;   // float4 per corner, BVH order; empty without the feature
  std::vector<float> cornerUVs;       // float2 per corner, BVH order; empty without the feature
  std::vector<uint32_t> texels, textureInfo;
  std::vector<float> environment;  // kernels/environment.h's layout; a black 1x1 map when there is none
  int environmentWidth = 1, environmentHeight = 1;
  float environmentUShift = 0.f;
  std::vector<std::string> warnings;  // textures that could not be read
};

// `features` may include more than the scene uses (to measure specialization); `environment`
// may be null (no map).
PreparedScene prepareScene(const Scene& scene, const Bvh& bvh, const SceneFeatures& features,
                           const EnvironmentMap* environment = nullptr);

// The prepared scene in one device's memory.
class DeviceScene {
 public:
  DeviceScene(DeviceContext& dc, const PreparedScene& scene, const Bvh& bvh);

  // Whether next-event estimation has anything to sample.
  bool hasLights() const { return lightCount > 0 || environmentPick > 0.f; }

  DeviceBvh bvh;
  SceneFeatures features;
  unsigned lightCount = 0;
  float environmentPick = 0.f;
  int environmentWidth = 1, environmentHeight = 1;
  float environmentUShift = 0.f;
  // The BVH's own and the rest; normals, uvs, texels and texture_info are one-element
  // placeholders when unused.
  SceneBuffers buffers;
};

}  // namespace fh
