// The first device pipeline (generate -> intersect -> shade_aov) against a brute-force
// CPU ray cast of the same camera. Pixels whose whole footprint sees one surface must
// match exactly; only pixels on silhouettes and edges may differ, and they are few.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "base/vec.h"
#include "render/render_aov.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

struct Reference {
  std::vector<long> triangle;  // per pixel, or -2 where the footprint sees several surfaces
};

// What a pixel shows in an AOV: the material for albedo, the plane for normals.
using SurfaceKey = std::function<long(long triangle)>;

// Traces the pixel's centre and four corners (inset slightly); a pixel is "interior" when
// all five see the same surface by `key`, and then holds the centre's triangle.
Reference bruteForceReference(const Scene& scene, const Camera& camera, int w, int h, const SurfaceKey& key) {
  const CameraFrame f = makeCameraFrame(camera, w, h);
  Reference ref;
  const float offsets[5][2] = {{0.5f, 0.5f}, {0.01f, 0.01f}, {0.99f, 0.01f}, {0.01f, 0.99f}, {0.99f, 0.99f}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      long center = -1;
      bool same = true;
      for (const auto& o : offsets) {
        const float3 d = normalize(cameraRayDirection(f, float(x) + o[0], float(y) + o[1], w, h));
        const double org[3] = {f.origin[0], f.origin[1], f.origin[2]}, dir[3] = {d[0], d[1], d[2]};
        const long t = test::bruteForceClosest(scene, org, dir).triangle;
        if (&o == &offsets[0]) center = t;
        same = same && (t < 0 ? -1 : key(t)) == (center < 0 ? -1 : key(center));
      }
      ref.triangle.push_back(same ? center : -2);
    }
  return ref;
}

class AovRender : public ::testing::Test {
 protected:
  Scene scene = loadDefaultScene();
  Bvh bvh = buildBvh(scene);
  DeviceContext dc{selectDevices(listDevices(), "").front()};
  static constexpr int kWidth = 48, kHeight = 40;  // not square: catches a swapped aspect
};

TEST_F(AovRender, AlbedoMatchesBruteForceOnInteriorPixels) {
  AovSettings s;
  s.width = kWidth;
  s.height = kHeight;
  s.spp = 2;
  s.mode = Aov::Albedo;
  const Image img = renderAov(dc, scene, bvh, scene.camera, s);
  const Reference ref = bruteForceReference(scene, scene.camera, kWidth, kHeight,
                                            [&](long t) { return long(scene.triangleMaterial[size_t(t)]); });
  int interior = 0;
  for (size_t p = 0; p < ref.triangle.size(); ++p) {
    if (ref.triangle[p] == -2) continue;
    ++interior;
    Vec3f expected{0.f, 0.f, 0.f};
    if (ref.triangle[p] >= 0) expected = scene.materials[size_t(scene.triangleMaterial[size_t(ref.triangle[p])])].kd;
    for (size_t c = 0; c < 3; ++c)
      ASSERT_NEAR(img.rgb[3 * p + c], expected[c], 1e-6f) << "pixel " << p % kWidth << "," << p / kWidth;
  }
  EXPECT_GT(interior, int(0.7 * kWidth * kHeight));  // the test must check most pixels
}

TEST_F(AovRender, NormalsAndDepthMatchBruteForceOnInteriorPixels) {
  AovSettings s;
  s.width = kWidth;
  s.height = kHeight;
  s.spp = 1;
  s.mode = Aov::Normal;
  const Image normals = renderAov(dc, scene, bvh, scene.camera, s);
  auto normalOf = [&](size_t t) {
    return normalize(cross(scene.corner(t, 1) - scene.corner(t, 0), scene.corner(t, 2) - scene.corner(t, 0)));
  };
  // Two triangles of one quad share a plane: key by the quantized normal.
  const Reference ref = bruteForceReference(scene, scene.camera, kWidth, kHeight, [&](long t) {
    const float3 n = normalOf(size_t(t));
    return long(std::lround(n[0] * 1e4f)) * 100000000L + long(std::lround(n[1] * 1e4f)) * 10000L +
           long(std::lround(n[2] * 1e4f));
  });
  int interior = 0;
  for (size_t p = 0; p < ref.triangle.size(); ++p) {
    if (ref.triangle[p] < 0) continue;
    ++interior;
    const float3 n = normalOf(size_t(ref.triangle[p]));
    for (size_t c = 0; c < 3; ++c)
      ASSERT_NEAR(normals.rgb[3 * p + c], 0.5f * n[c] + 0.5f, 1e-3f) << "pixel " << p % kWidth << "," << p / kWidth;
  }
  EXPECT_GT(interior, int(0.5 * kWidth * kHeight));  // box edges split many pixels
  // Depth is positive, finite on hits, and grows toward the back wall from the front edge.
  s.mode = Aov::Depth;
  const Image depth = renderAov(dc, scene, bvh, scene.camera, s);
  const size_t center = size_t(kHeight / 2 * kWidth + kWidth / 2);
  EXPECT_GT(depth.rgb[3 * center], 3.5f);
  EXPECT_LT(depth.rgb[3 * center], 5.5f);
}

}  // namespace
}  // namespace fh
