// A scene as flat, device-ready arrays: what the loader produces and the BVH, the
// kernels and the tests consume.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "scene/camera.h"

namespace fh {

using Vec3f = std::array<float, 3>;

// The MTL illum models fredholm renders as a smooth dielectric (kernels/bsdf.h).
inline bool isGlassIllum(int illum) { return illum == 4 || illum == 6 || illum == 7 || illum == 9; }

// The MTL fields later stages use. Tf only means transmission for the glass illum
// models (4, 6, 7, 9): `isGlass()` says when.
struct Material {
  std::string name;
  Vec3f kd{0.5f, 0.5f, 0.5f};
  Vec3f ks{0.f, 0.f, 0.f};
  Vec3f ke{0.f, 0.f, 0.f};  // emitted radiance, front (counter-clockwise) side only
  Vec3f tf{1.f, 1.f, 1.f};
  float ns = 0.f;
  float ni = 1.f;
  float d = 1.f;
  int illum = 2;
  int kdTexture = -1;  // index into Scene::textures, -1 for none

  bool isEmissive() const { return ke[0] > 0.f || ke[1] > 0.f || ke[2] > 0.f; }
  bool isGlass() const { return isGlassIllum(illum); }
};

// Scales a reflectance whose largest channel is above one (it would reflect more light than
// it receives) down to a largest channel of one, its hue kept; returns whether it did.
inline bool capReflectance(float rgb[3]) {
  const float most = std::max({rgb[0], rgb[1], rgb[2]});
  if (!(most > 1.f)) return false;
  for (int c = 0; c < 3; ++c) rgb[c] /= most;
  return true;
}

struct Texture {
  std::string path;  // resolved on disk (case-insensitive fallback applied)
};

// One emissive triangle, as the light sampler will see it.
struct Light {
  unsigned triangle = 0;
  float area = 0.f;
  Vec3f power{0.f, 0.f, 0.f};  // emittedPower(area, Ke)
};

// The power of a one-sided Lambertian emitter of radiance ke over `area`: pi * area * Ke.
inline Vec3f emittedPower(float area, const Vec3f& ke) {
  const float k = float(M_PI) * area;
  return {k * ke[0], k * ke[1], k * ke[2]};
}

struct Scene {
  std::string sourcePath;
  std::vector<float> positions;          // xyz per vertex
  std::vector<unsigned> indices;         // three vertex indices per triangle
  std::vector<int> triangleMaterial;     // material per triangle
  std::vector<float> cornerNormals;      // 9 floats per triangle; empty if the file has none
  std::vector<float> cornerUVs;          // 6 floats per triangle; empty if the file has none
  std::vector<Material> materials;       // the last one may be the default grey
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<std::string> warnings;
  bool hasCamera = false;                // a camera sidecar was found next to the OBJ
  Camera camera;                         // in the file's units
  // The renderer's lengths are the file's times this: a power of two, so the scaling is
  // exact and the image the same bits, chosen by the loader (scene_loader.h) to bring a
  // scene far from unit size near it. Single precision holds a length's square (area
  // densities) and fourth power (bdpt's weights) only for lengths from about 2^-32 to 2^32.
  float worldScale = 1.f;

  size_t triangleCount() const { return indices.size() / 3; }
  size_t vertexCount() const { return positions.size() / 3; }
  Vec3f vertex(unsigned i) const { return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]}; }
  // Corner k (0..2) of triangle t.
  Vec3f corner(size_t t, int k) const { return vertex(indices[3 * t + size_t(k)]); }
  void bounds(Vec3f& lo, Vec3f& hi) const;
};

}  // namespace fh
