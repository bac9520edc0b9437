// The --aovs layers: first-surface albedo, normal and depth recorded by shade in the same
// render as the image (kernels/aovs.h), against what scenes built for it must give, pixel by
// pixel; the image itself unchanged by recording them; and the layered EXR the command line
// writes, with its channel names.
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "render/render.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

struct Layers {
  Film film;
  std::vector<float> albedo, normal, depth;
};

constexpr int kSize = 16;

// The layers of 8 samples per pixel under a white sky.
Layers renderLayers(const Scene& scene, const Camera& camera) {
  RenderSettings s = test::renderSettings();
  s.width = s.height = kSize;
  s.spp = 8;
  s.env = {1.f, 1.f, 1.f};
  s.surfaceAovs = true;
  const RenderResult r = test::render(scene, camera, s);
  return {r.film, r.film.albedo(), r.film.normal(), r.film.depth()};
}

// The distance along pixel (i, j)'s centre ray to the plane z = 0 from a camera on the z
// axis at `height` looking down -z (kernels/camera.h: the image spans tan(fov/2) each way).
double centreRayDepth(int i, int j, double height, double fovYDeg) {
  const double t = std::tan(fovYDeg * 3.14159265358979323846 / 360.0);
  const double x = (2.0 * (i + 0.5) / kSize - 1.0) * t, y = (1.0 - 2.0 * (j + 0.5) / kSize) * t;
  return height * std::sqrt(1.0 + x * x + y * y);
}

Scene writeAndLoad(const std::string& name, const std::string& mtl, const std::string& obj) {
  const std::string dir = test::tempDir("aovs");
  test::writeFile(dir + "/" + name + ".mtl", mtl);
  test::writeFile(dir + "/" + name + ".obj", "mtllib " + name + ".mtl\n" + obj);
  return loadScene(dir + "/" + name + ".obj");
}

Camera lookingDown(float height) {
  Camera c;
  c.eye = {0.f, 0.f, height};
  c.target = {0.f, 0.f, 0.f};
  c.up = {0.f, 1.f, 0.f};
  c.fovYDeg = 30.f;
  return c;
}

// Pixel (i, j) saw, with every sample, a surface of albedo `albedo` whose normal is
// (0, 0, normalZ), at the camera ray's distance to the plane z = 0 from `height`.
void expectSurfaceAt(const Layers& l, int i, int j, const std::array<float, 3>& albedo, float normalZ,
                     double height) {
  const size_t p = size_t(j * kSize + i);
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(l.albedo[3 * p + c], albedo[c], 1e-6f);
  EXPECT_NEAR(l.normal[3 * p + 2], normalZ, 1e-6f);
  // The pixel's samples spread over its footprint; the mean distance is the centre's to
  // second order.
  EXPECT_NEAR(l.depth[p], centreRayDepth(i, j, height, 30.0), 1e-3 * l.depth[p]);
}

// A diffuse plane under the left half of the view, nothing under the right half: the
// plane's albedo and normal exactly, its distance per pixel, and nothing where rays escape.
TEST(SurfaceAovs, DiffusePlaneAndEmptySky) {
  const Scene scene = writeAndLoad("half", "newmtl paint\nKd 0.2 0.4 0.6\n",
                                   "v -10 -10 0\nv 0 -10 0\nv 0 10 0\nv -10 10 0\nusemtl paint\nf 1 2 3 4\n");
  const Layers l = renderLayers(scene, lookingDown(3.f));
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) {
      const size_t p = size_t(j * kSize + i);
      SCOPED_TRACE("pixel " + std::to_string(i) + "," + std::to_string(j));
      if (i < kSize / 2) {  // all on the plane (x < 0)
        expectSurfaceAt(l, i, j, {0.2f, 0.4f, 0.6f}, 1.f, 3.0);
      } else {  // all escape
        EXPECT_EQ(l.albedo[3 * p], 0.f);
        EXPECT_EQ(l.normal[3 * p + 2], 0.f);
        EXPECT_EQ(l.depth[p], kNoDepth);
      }
    }
}

// A mirror filling the view reflects it onto a diffuse wall behind the camera: albedo and
// normal are the wall's (the first non-specular surface; its normal on the viewer's side),
// depth is the mirror's (the camera ray's).
TEST(SurfaceAovs, LookThroughMirrorsToTheFirstNonSpecularSurface) {
  const Scene scene = writeAndLoad(
      "mirror", "newmtl mirror\nillum 5\nKd 0 0 0\nKs 1 1 1\nNs 10000\nnewmtl wall\nKd 0.1 0.8 0.3\n",
      "v -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\n"
      "v -30 -30 5\nv 30 -30 5\nv 30 30 5\nv -30 30 5\n"
      "usemtl mirror\nf 1 2 3 4\nusemtl wall\nf 8 7 6 5\n");
  const Layers l = renderLayers(scene, lookingDown(2.f));
  for (int j = 0; j < kSize; ++j)
    for (int i = 0; i < kSize; ++i) {
      SCOPED_TRACE("pixel " + std::to_string(i) + "," + std::to_string(j));
      expectSurfaceAt(l, i, j, {0.1f, 0.8f, 0.3f}, -1.f, 2.0);
    }
}

// Recording the layers changes nothing in the image: the same bits, every method, on a scene
// with every material feature (mirror, glass, glossy, textures, shading normals).
TEST(SurfaceAovs, TheImageIsTheSameBitsWithOrWithoutThem) {
  const std::string dir = test::tempDir("aovs-features");
  const Scene scene = loadScene(test::writeFeatureScene(dir));
  DeviceContext& dc = test::defaultDevice();
  const Bvh bvh = buildBvh(scene);
  for (Method m : {Method::PT, Method::NEE, Method::MIS}) {
    RenderSettings s = test::renderSettings();
    s.width = s.height = kSize;
    s.spp = 16;
    s.method = m;
    const RenderResult plain = fh::render(dc, scene, bvh, scene.camera, s);
    s.surfaceAovs = true;
    const RenderResult layered = fh::render(dc, scene, bvh, scene.camera, s);
    EXPECT_TRUE(plain.film.sum == layered.film.sum) << methodName(m);
    EXPECT_TRUE(plain.film.sumSq == layered.film.sumSq) << methodName(m);
    // Depths are positive: inside the box's few units, or kNoDepth past its open front.
    for (float d : layered.film.depth()) ASSERT_TRUE((d > 0.f && d < 10.f) || d == kNoDepth) << methodName(m);
  }
}

// The command line: one EXR with the image and every layer under the names compositors and
// denoisers read; its R, G, B the same as without layers; spp and variance as the film has them.
TEST(AovsCli, OneExrWithNamedLayers) {
  const std::string dir = test::tempDir("aovs-cli");
  const std::string common = " --width 8 --height 8 --spp 4 --seed 3";
  ASSERT_EQ(test::runFredholm("render -o " + dir + "/plain.exr" + common).exitCode, 0);
  const auto r = test::runFredholm("render -o " + dir + "/layers.exr --aovs albedo,normal,depth,variance,spp" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;

  auto in = OIIO::ImageInput::open(dir + "/layers.exr");
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<std::string> names(spec.channelnames.begin(), spec.channelnames.end());
  const std::vector<std::string> expected = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B",
                                             "normal.X", "normal.Y", "normal.Z", "depth.Z",
                                             "variance.R", "variance.G", "variance.B", "spp.Y"};
  std::vector<std::string> sortedNames = names, sortedExpected = expected;
  std::sort(sortedNames.begin(), sortedNames.end());
  std::sort(sortedExpected.begin(), sortedExpected.end());
  ASSERT_EQ(sortedNames, sortedExpected);
  std::vector<float> pixels(size_t(spec.width * spec.height * spec.nchannels));
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
  auto channel = [&](const std::string& name, size_t pixel) {
    const size_t c = size_t(std::find(names.begin(), names.end(), name) - names.begin());
    return pixels[pixel * size_t(spec.nchannels) + c];
  };

  const Image plain = readImage(dir + "/plain.exr");
  bool someVariance = false;
  for (size_t p = 0; p < size_t(spec.width * spec.height); ++p) {
    EXPECT_EQ(channel("R", p), plain.rgb[3 * p]);
    EXPECT_EQ(channel("G", p), plain.rgb[3 * p + 1]);
    EXPECT_EQ(channel("B", p), plain.rgb[3 * p + 2]);
    EXPECT_EQ(channel("spp.Y", p), 4.f);
    EXPECT_GE(channel("variance.R", p), 0.f);
    someVariance |= channel("variance.R", p) > 0.f;
    // The Cornell box fills the square view: every pixel sees a wall.
    EXPECT_GT(channel("depth.Z", p), 1.f);
    EXPECT_LT(channel("depth.Z", p), 8.f);
    const float nx = channel("normal.X", p), ny = channel("normal.Y", p), nz = channel("normal.Z", p);
    EXPECT_LE(nx * nx + ny * ny + nz * nz, 1.f + 1e-5f);
    for (const char* a : {"albedo.R", "albedo.G", "albedo.B"}) {
      EXPECT_GE(channel(a, p), 0.f);
      EXPECT_LE(channel(a, p), 1.f);
    }
  }
  EXPECT_TRUE(someVariance);
}

TEST(AovsCli, BadListsAndNonExrOutputsAreErrors) {
  const std::string dir = test::tempDir("aovs-errors");
  const auto png = test::runFredholm("render --spp 1 --width 8 --height 8 --aovs albedo -o " + dir + "/x.png");
  EXPECT_NE(png.exitCode, 0);
  EXPECT_NE(png.output.find("fredholm: error: --aovs"), std::string::npos) << png.output;
  const auto unknown = test::runFredholm("render --spp 1 --width 8 --height 8 --aovs albedo,glow -o " + dir + "/y.exr");
  EXPECT_NE(unknown.exitCode, 0);
  EXPECT_NE(unknown.output.find("'glow'"), std::string::npos) << unknown.output;
  const auto both = test::runFredholm("render --spp 1 --width 8 --height 8 --aov albedo --aovs depth -o " + dir +
                                      "/z.exr");
  EXPECT_NE(both.exitCode, 0);
  for (const char* f : {"/x.png", "/y.exr", "/z.exr"}) EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;
}

}  // namespace
}  // namespace fh
