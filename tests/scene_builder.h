// Scenes built in code for closed-form tests: quads and boxes with chosen materials.
#pragma once
#include "base/vec.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"

namespace fh::test {

class SceneBuilder {
 public:
  // A material with diffuse albedo `kd` and emitted radiance `ke` (grey values).
  int material(float kd, float ke = 0.f) {
    Material m;
    m.name = "m" + std::to_string(scene_.materials.size());
    m.kd = {kd, kd, kd};
    m.ke = {ke, ke, ke};
    scene_.materials.push_back(m);
    return int(scene_.materials.size() - 1);
  }

  // A smooth dielectric of index `ni` (illum 7): the medium lies behind its faces' fronts.
  int glass(float ni) {
    const int m = material(0.f);
    scene_.materials[size_t(m)].illum = 7;
    scene_.materials[size_t(m)].ni = ni;
    return m;
  }

  // A perfect mirror (illum 3, Ns past the mirror threshold, Ks 1: Schlick's Fresnel is 1).
  int mirror() {
    const int m = material(0.f);
    scene_.materials[size_t(m)].illum = 3;
    scene_.materials[size_t(m)].ks = {1.f, 1.f, 1.f};
    scene_.materials[size_t(m)].ns = 10000.f;
    return m;
  }

  // Triangle a b c, counter-clockwise as seen from its front.
  void triangle(const float3& a, const float3& b, const float3& c, int material) {
    const unsigned base = unsigned(scene_.vertexCount());
    for (const float3& p : {a, b, c}) scene_.positions.insert(scene_.positions.end(), p.begin(), p.end());
    for (unsigned k : {0u, 1u, 2u}) scene_.indices.push_back(base + k);
    scene_.triangleMaterial.push_back(material);
  }

  // Quad a b c d, counter-clockwise as seen from its front.
  void quad(const float3& a, const float3& b, const float3& c, const float3& d, int material) {
    const unsigned base = unsigned(scene_.vertexCount());
    for (const float3& p : {a, b, c, d}) scene_.positions.insert(scene_.positions.end(), p.begin(), p.end());
    for (unsigned k : {0u, 1u, 2u, 0u, 2u, 3u}) scene_.indices.push_back(base + k);
    scene_.triangleMaterial.insert(scene_.triangleMaterial.end(), {material, material});
  }

  // Quad a b c d wound so that its front faces toward `toward`.
  void quadFacing(const float3& a, const float3& b, const float3& c, const float3& d, const float3& toward,
                  int material) {
    if (dot(cross(b - a, c - a), toward - a) >= 0.f) quad(a, b, c, d, material);
    else quad(a, d, c, b, material);
  }

  // The six inner faces of the box [lo, hi], fronts facing inward; the back face (z = lo)
  // of material `back` where that is not negative.
  void closedBoxInside(const float3& lo, const float3& hi, int material, int back = -1) {
    const float x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
    const float3 c = (lo + hi) * 0.5f;
    quadFacing({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}, c, material);  // floor
    quadFacing({x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, c, material);  // ceiling
    quadFacing({x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}, c, material);  // left
    quadFacing({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}, c, material);  // right
    quadFacing({x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}, c, back < 0 ? material : back);  // back
    quadFacing({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}, c, material);  // front
  }

  Scene build() {
    Scene s = scene_;
    s.sourcePath = "<test scene>";
    collectLights(s);
    return s;
  }

 private:
  Scene scene_;
};

// One slanted quad, `copies` times on top of itself: duplicated faces (as in the archive's
// Cornell box) put equal hits in different BVH leaves, the intersect kernel's tie.
inline void coincidentQuads(SceneBuilder& b, int copies, int material) {
  for (int copy = 0; copy < copies; ++copy)
    b.quad({-1.f, -0.7f, 0.3f}, {1.2f, -0.9f, -0.4f}, {0.9f, 1.1f, -0.2f}, {-1.1f, 0.8f, 0.5f}, material);
}

}  // namespace fh::test
