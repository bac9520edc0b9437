// The HDR environment light (--env-map): scenes with closed forms under maps lit in one
// part of the sky, a white furnace, the map seen straight from the camera texel by texel
// (the direction convention and --env-rotate), a constant map against --env, the map beside
// triangle lights under every method, and the command line's errors.
//
// Statistical checks compare means with a tolerance of kSigmas standard errors, from the
// film's per-pixel sample variance (which overstates the error of the low-discrepancy
// sampler: the check is loose, not flaky), plus a small absolute slack where the error is 0.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "base/test_hooks.h"
#include "render/render.h"
#include "scene/environment_map.h"
#include "scene/icosphere.h"
#include "scene_builder.h"
#include "test_support.h"

namespace fh {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSigmas = 4.0;
constexpr int kSize = 16;

using TexelFunction = std::function<float3(int x, int y)>;

std::shared_ptr<const EnvironmentMap> mapOf(int width, int height, const TexelFunction& texel, float rotateDeg = 0.f,
                                            float scale = 1.f) {
  std::vector<float> rgb;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float3 c = texel(x, y);
      rgb.insert(rgb.end(), c.begin(), c.end());
    }
  return std::make_shared<const EnvironmentMap>(
      makeEnvironmentMap("<test map>", width, height, rgb, rotateDeg, scale));
}

// Radiance L over the upper hemisphere (the top half of the rows), black below.
std::shared_ptr<const EnvironmentMap> upperHemisphere(float radiance, float rotateDeg = 0.f) {
  return mapOf(64, 32, [=](int, int y) { return y < 16 ? float3{radiance, radiance, radiance} : float3{}; },
               rotateDeg);
}

// Radiance L over the quarter of the sphere with y > 0 and x > 0 (columns u > 0.5), black
// elsewhere.
std::shared_ptr<const EnvironmentMap> upperEastQuarter(float radiance, float rotateDeg) {
  return mapOf(64, 32,
               [=](int x, int y) { return y < 16 && x >= 32 ? float3{radiance, radiance, radiance} : float3{}; },
               rotateDeg);
}

Camera lookingAt(const float3& eye, const float3& target, const float3& up, float fov = 30.f) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.fovYDeg = fov;
  return c;
}

// The mean over pixels [first, last) of the channel average, and its standard error.
struct Estimate {
  double mean = 0.0, error = 0.0;
};

Estimate estimate(const Film& film, size_t first = 0, size_t last = 0) {
  if (last == 0) last = film.pixels();
  const Image image = film.image();
  Estimate e;
  double variance = 0.0;
  for (size_t p = first; p < last; ++p) {
    const std::array<double, 3> v = film.varianceOfMean(p);
    for (size_t c = 0; c < 3; ++c) {
      e.mean += image.rgb[3 * p + c];
      variance += v[c];
    }
  }
  const double n = 3.0 * double(last - first);
  e.mean /= n;
  e.error = std::sqrt(variance) / n;
  return e;
}

void expectMean(const Estimate& e, double expected, const std::string& what) {
  EXPECT_NEAR(e.mean, expected, kSigmas * e.error + 1e-4 * std::max(1.0, expected))
      << what << ": " << e.mean << " +- " << e.error << ", expected " << expected;
}

// A diffuse square of albedo `albedo`, 4 wide, through the origin, facing `normal` (unit),
// and a camera on that side looking at its centre; the camera sees nothing but the square.
// With `hiddenLamp` > 0, a lamp of that radiance far below faces down, away from the square:
// it lights nothing the camera sees, but light sampling picks it about half the time.
Scene squareFacing(const float3& normal, float albedo, float hiddenLamp = 0.f) {
  test::SceneBuilder b;
  const int m = b.material(albedo);
  if (hiddenLamp > 0.f)
    b.quadFacing({-0.5f, -5.f, -0.5f}, {0.5f, -5.f, -0.5f}, {0.5f, -5.f, 0.5f}, {-0.5f, -5.f, 0.5f}, {0.f, -6.f, 0.f},
                 b.material(0.f, hiddenLamp));
  const float3 helper = std::fabs(normal[1]) < 0.9f ? float3{0.f, 1.f, 0.f} : float3{1.f, 0.f, 0.f};
  const float3 u = normalize(cross(helper, normal)), v = cross(normal, u);
  auto corner = [&](float a, float c) { return u * (2.f * a) + v * (2.f * c); };
  b.quadFacing(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), normal, m);
  return b.build();
}

Camera facingSquare(const float3& normal) {
  const float3 up = std::fabs(normal[1]) < 0.9f ? float3{0.f, 1.f, 0.f} : float3{1.f, 0.f, 0.f};
  return lookingAt(normal * 2.f, {0.f, 0.f, 0.f}, up);
}

class EveryMethod : public ::testing::TestWithParam<Method> {};
INSTANTIATE_TEST_SUITE_P(Environment, EveryMethod, ::testing::Values(Method::PT, Method::NEE, Method::MIS, Method::BDPT),
                         [](const ::testing::TestParamInfo<Method>& method) { return std::string(methodName(method.param)); });

// A plane tilted by alpha from horizontal sees the sky through a view factor (1 + cos alpha)/2:
// under radiance L over the upper hemisphere its irradiance is pi L (1 + cos alpha) / 2, and a
// diffuse plane of albedo rho returns rho L (1 + cos alpha) / 2. A lamp that lights nothing
// in view shares light sampling with the map: the pick's probability must cancel.
TEST_P(EveryMethod, TiltedPlaneUnderTheUpperHemisphereMatchesItsViewFactor) {
  const float albedo = 0.5f, radiance = 2.f;
  RenderSettings s = test::renderSettings();
  s.width = s.height = kSize;
  s.spp = 64;
  s.method = GetParam();
  s.envMap = upperHemisphere(radiance);
  for (double degrees : {0.0, 60.0, 120.0}) {
    const double alpha = degrees * kPi / 180.0;
    const float3 normal{float(std::sin(alpha)), float(std::cos(alpha)), 0.f};
    const Film film = test::render(squareFacing(normal, albedo, 200.f), facingSquare(normal), s).film;
    expectMean(estimate(film), albedo * radiance * (1.0 + std::cos(alpha)) / 2.0,
               "tilted " + std::to_string(degrees) + " degrees");
  }
}

// A vertical plane under radiance over the quarter y > 0, x > 0 turned by --env-rotate: facing
// the quarter's side it gets half the hemisphere's cosine-weighted light, facing across it
// a quarter, facing away none: rho L / 2, rho L / 4, 0. This pins down which way u runs
// (towards +x) and which way a positive rotation turns the map (counter-clockwise from above:
// +x towards -z).
TEST_P(EveryMethod, VerticalPlaneUnderAQuarterOfTheSkyTurnedByRotate) {
  const float albedo = 0.5f, radiance = 2.f;
  const float3 east{1.f, 0.f, 0.f}, west{-1.f, 0.f, 0.f}, south{0.f, 0.f, 1.f}, north{0.f, 0.f, -1.f};
  struct Case {
    float3 normal;
    float rotate;
    double share;  // of rho L
  };
  RenderSettings s = test::renderSettings();
  s.width = s.height = kSize;
  s.spp = 64;
  s.method = GetParam();
  for (const Case& c : {Case{east, 0.f, 0.5}, Case{west, 0.f, 0.0}, Case{south, 0.f, 0.25}, Case{north, 90.f, 0.5},
                        Case{east, 90.f, 0.25}, Case{west, 180.f, 0.5}, Case{east, 180.f, 0.0}}) {
    s.envMap = upperEastQuarter(radiance, c.rotate);
    const Film film = test::render(squareFacing(c.normal, albedo), facingSquare(c.normal), s).film;
    expectMean(estimate(film), albedo * radiance * c.share,
               "normal " + std::to_string(c.normal[0]) + "," + std::to_string(c.normal[2]) + " rotate " +
                   std::to_string(c.rotate));
  }
}

// A convex sphere of albedo 1 under a white map returns exactly the radiance it receives:
// the image is the map's 1 everywhere, sphere or not.
Film whiteFurnace(Method method, int spp) {
  test::SceneBuilder b;
  const int m = b.material(1.f);
  Scene scene = b.build();
  const IndexedMesh sphere = icosphere(3);
  for (const float3& v : sphere.vertices) scene.positions.insert(scene.positions.end(), v.begin(), v.end());
  for (const auto& f : sphere.faces) {
    scene.indices.insert(scene.indices.end(), f.begin(), f.end());
    scene.triangleMaterial.push_back(m);
  }
  RenderSettings s = test::renderSettings();
  s.width = s.height = kSize;
  s.spp = spp;
  s.method = method;
  s.envMap = mapOf(32, 16, [](int, int) { return float3{1.f, 1.f, 1.f}; });
  return test::render(scene, lookingAt({0.f, 0.f, 3.f}, {0.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, 45.f), s).film;
}

void expectWhiteFurnace(Method method) {
  const Film film = whiteFurnace(method, 64);
  expectMean(estimate(film), 1.0, "whole image");
  const Image image = film.image();
  for (size_t p = 0; p < film.pixels(); ++p) {
    const std::array<double, 3> v = film.varianceOfMean(p);
    for (size_t c = 0; c < 3; ++c)
      ASSERT_NEAR(image.rgb[3 * p + c], 1.0, 5.0 * std::sqrt(v[c]) + 1e-4) << "pixel " << p;
  }
}

TEST_P(EveryMethod, WhiteFurnaceTheAlbedoOneSphereVanishes) { expectWhiteFurnace(GetParam()); }

// bdpt's strategies toward the map, each alone at weight one (the test hook of
// kernels/bdpt.cl, FH_BDPT_ONLY_S): the camera's escaping rays (s = 0), directions drawn from
// the map (1), and light paths from the map's disk seen by the camera (2; off a convex sphere
// no path has more than one bounce). Each must keep the furnace white, held in quarters of
// the image: light tracing's pixels gather a few splats a pass, too few for a pixel's own
// variance estimate to be trusted at five sigma.
TEST(EnvironmentMap, BidirectionalStrategiesAloneKeepTheWhiteFurnace) {
  for (int only : {0, 1, 2}) {
    TestHooks hooks = testHooks();
    hooks.bdptOnlyLightVertices = only;
    const ScopedTestHooks strategy(hooks);
    const std::string what = "bdpt, only s = " + std::to_string(only);
    const Film film = whiteFurnace(Method::BDPT, 256);
    for (size_t quarter = 0; quarter < 4; ++quarter)
      expectMean(estimate(film, quarter * film.pixels() / 4, (quarter + 1) * film.pixels() / 4), 1.0,
                 what + ", image quarter " + std::to_string(quarter));
  }
}

// The map and a triangle light together: the light pick shares light sampling's samples
// between them, and every method must give the same image (an open box lit by both).
TEST(EnvironmentMap, BesideATriangleLightEveryMethodAgrees) {
  test::SceneBuilder b;
  const int white = b.material(0.7f), lamp = b.material(0.f, 5.f);
  b.quadFacing({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, white);      // floor
  b.quadFacing({-1, 0, -1}, {-1, 2, -1}, {1, 2, -1}, {1, 0, -1}, {0, 1, 0}, white);    // back wall
  b.quadFacing({-1, 0, -1}, {-1, 0, 1}, {-1, 2, 1}, {-1, 2, -1}, {0, 1, 0}, white);    // left wall
  b.quadFacing({0.4f, 1.5f, -0.6f}, {0.8f, 1.5f, -0.6f}, {0.8f, 1.5f, -0.2f}, {0.4f, 1.5f, -0.2f}, {0, 0, 0}, lamp);
  const Scene scene = b.build();
  const Camera camera = lookingAt({1.5f, 1.2f, 3.f}, {0.f, 0.6f, 0.f}, {0.f, 1.f, 0.f}, 50.f);
  RenderSettings s = test::renderSettings();
  s.width = s.height = kSize;
  s.spp = 256;
  s.envMap = upperEastQuarter(1.5f, 30.f);
  std::vector<Estimate> halves[4];
  const Method methods[] = {Method::PT, Method::NEE, Method::MIS, Method::BDPT};
  for (int i = 0; i < 4; ++i) {
    s.method = methods[i];
    const Film film = test::render(scene, camera, s).film;
    const size_t half = film.pixels() / 2;
    halves[i] = {estimate(film, 0, half), estimate(film, half, film.pixels())};
  }
  for (int i = 1; i < 4; ++i)
    for (int h = 0; h < 2; ++h) {
      const Estimate &a = halves[0][size_t(h)], &e = halves[i][size_t(h)];
      EXPECT_NEAR(e.mean, a.mean, kSigmas * std::hypot(a.error, e.error))
          << methodName(methods[i]) << " against pt, image half " << h;
    }
}

// A map of one radiance everywhere lights the scene as --env does (which is found only by
// BSDF sampling), under each method that samples the map.
TEST(EnvironmentMap, AConstantMapEqualsConstantEnv) {
  test::SceneBuilder b;
  const int grey = b.material(0.6f);
  b.quadFacing({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, grey);
  b.quadFacing({-1, 0, -1}, {-1, 2, -1}, {1, 2, -1}, {1, 0, -1}, {0, 1, 0}, grey);
  const Scene scene = b.build();
  const Camera camera = lookingAt({1.f, 1.5f, 3.f}, {0.f, 0.5f, 0.f}, {0.f, 1.f, 0.f}, 50.f);
  const float3 env{0.8f, 0.5f, 0.3f};
  RenderSettings constant = test::renderSettings();
  constant.width = constant.height = kSize;
  constant.spp = 256;
  constant.method = Method::PT;
  constant.env = env;
  const Film reference = test::render(scene, camera, constant).film;
  for (Method method : {Method::NEE, Method::MIS, Method::BDPT}) {
    RenderSettings s = test::renderSettings();
    s.width = s.height = kSize;
    s.spp = 256;
    s.method = method;
    s.envMap = mapOf(16, 8, [&](int, int) { return env; });
    const Film film = test::render(scene, camera, s).film;
    for (size_t block = 0; block < 4; ++block) {
      const size_t first = block * film.pixels() / 4, last = (block + 1) * film.pixels() / 4;
      const Estimate a = estimate(reference, first, last), e = estimate(film, first, last);
      EXPECT_NEAR(e.mean, a.mean, kSigmas * std::hypot(a.error, e.error))
          << methodName(method) << ", image quarter " << block;
    }
  }
}

// Seen straight from the camera (no surface in view), every pixel whose footprint lies in
// one texel shows that texel exactly: row 0 up, u = 0.5 straight ahead along -z, u growing
// to the right (+x), and --env-rotate turning the map counter-clockwise seen from above.
TEST(EnvironmentMap, TheCameraSeesTheMapAsDrawnTexelByTexel) {
  constexpr int kWidth = 8, kHeight = 4;
  test::SceneBuilder b;
  const int m = b.material(0.5f);
  b.quadFacing({-0.1f, -0.1f, 5.f}, {0.1f, -0.1f, 5.f}, {0.1f, 0.1f, 5.f}, {-0.1f, 0.1f, 5.f}, {0, 0, 10}, m);
  const Scene scene = b.build();  // one small quad behind the camera
  const Camera camera = lookingAt({0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, {0.f, 1.f, 0.f}, 100.f);
  const double t = std::tan(50.0 * kPi / 180.0);
  RenderSettings settings = test::renderSettings();
  settings.width = settings.height = kSize;
  settings.spp = 16;
  for (float rotate : {0.f, 90.f, -135.f}) {
    const auto map = mapOf(kWidth, kHeight, [](int x, int y) { return float3{float(x + 1), float(y + 1), 0.5f}; },
                           rotate);
    // The texel the unit direction d looks up (environment_map.h's conventions).
    auto texelOf = [&](double dx, double dy, double dz) {
      const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double v = std::acos(dy / len) / kPi;
      double u = std::atan2(dx, -dz) / (2.0 * kPi) + 0.5 + rotate / 360.0;
      u -= std::floor(u);
      return std::array<int, 2>{std::min(int(u * kWidth), kWidth - 1), std::min(int(v * kHeight), kHeight - 1)};
    };
    settings.envMap = map;
    const Image image = test::render(scene, camera, settings).film.image();
    int checked = 0;
    for (int j = 0; j < kSize; ++j)
      for (int i = 0; i < kSize; ++i) {
        // The direction through image point (a, b) in pixels, as kernels/camera.h maps it.
        auto at = [&](double a, double c) {
          return texelOf((2.0 * a / kSize - 1.0) * t, (1.0 - 2.0 * c / kSize) * t, -1.0);
        };
        const std::array<int, 2> centre = at(i + 0.5, j + 0.5);
        bool oneTexel = true;
        for (int s = 0; s <= 4; ++s)
          for (int r = 0; r <= 4; ++r) oneTexel = oneTexel && at(i + 0.25 * s, j + 0.25 * r) == centre;
        if (!oneTexel) continue;
        ++checked;
        const size_t p = size_t(j * kSize + i);
        EXPECT_EQ(image.rgb[3 * p], float(centre[0] + 1)) << "pixel " << i << "," << j << " rotate " << rotate;
        EXPECT_EQ(image.rgb[3 * p + 1], float(centre[1] + 1)) << "pixel " << i << "," << j << " rotate " << rotate;
      }
    EXPECT_GT(checked, kSize * kSize / 3) << "too few pixels inside one texel to check";
  }
}

// The sampling tables: each texel's density matches its luminance times sin(theta), they
// integrate to one over the sphere, and the CDFs end at one.
TEST(EnvironmentMap, TablesIntegrateToOneOverTheSphere) {
  const auto map = mapOf(12, 6, [](int x, int y) { return float3{float(x % 3), float(y), 0.25f * float(x + y)}; });
  // A texel's density per uv area over its luminance times sin(theta) at its row: one
  // constant for every texel that is not black.
  auto densityPerWeight = [&](int x, int y) {
    const float* t = &map->texels[4 * size_t(y * map->width + x)];
    return t[3] / ((0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]) * std::sin(kPi * (y + 0.5) / map->height));
  };
  double probability = 0.0;
  for (int y = 0; y < map->height; ++y) {
    for (int x = 0; x < map->width; ++x) {
      probability += map->texels[4 * size_t(y * map->width + x) + 3] / double(map->width * map->height);
      if (x % 3 != 0 || y != 0) {
        EXPECT_NEAR(densityPerWeight(x, y) / densityPerWeight(1, 0), 1.0, 1e-5) << x << "," << y;
      }
    }
    EXPECT_EQ(map->rowCdf[size_t((y + 1) * map->width - 1)], 1.f);
  }
  EXPECT_NEAR(probability, 1.0, 1e-5);
  EXPECT_EQ(map->marginalCdf.back(), 1.f);
  EXPECT_EQ(map->texels[3], 0.f) << "a black texel is never sampled";
  EXPECT_GT(map->luminanceIntegral, 0.0);
}

TEST(EnvironmentMap, NegativeOrNonFiniteTexelsAreErrors) {
  EXPECT_THROW(mapOf(4, 2, [](int x, int) { return float3{x == 3 ? -1.f : 1.f, 1.f, 1.f}; }), Error);
  EXPECT_THROW(mapOf(4, 2, [](int, int y) { return float3{1.f, y ? NAN : 1.f, 1.f}; }), Error);
  EXPECT_THROW(mapOf(4, 2, [](int, int) { return float3{1.f, 1.f, 1.f}; }, 0.f, -2.f), Error);
}

// The command line: a map in a file, its metadata, and one-line errors for what is wrong.
TEST(EnvironmentMapCli, RendersFromExrAndHdrAndRejectsBadInput) {
  const std::string dir = test::tempDir("env-map-cli");
  const std::string scene = test::writeFeatureScene(dir);
  Image map;
  map.width = 16;
  map.height = 8;
  for (int p = 0; p < 16 * 8; ++p) map.rgb.insert(map.rgb.end(), {0.5f, 0.6f, float(p % 16) / 4.f});
  writeImage(dir + "/sky.exr", map, {});
  writeImage(dir + "/sky.hdr", map, {});
  const std::string base = "render '" + scene + "' --width 16 --height 16 --spp 4 --force ";
  for (const char* file : {"sky.exr", "sky.hdr"}) {
    const auto ok = test::runFredholm(base + "-o '" + dir + "/out.exr' --env-map '" + dir + "/" + file +
                                      "' --env-rotate 45 --env-scale 2");
    ASSERT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_NE(ok.output.find("environment map"), std::string::npos) << ok.output;
  }

  // A checkpoint belongs to its map and rotation.
  const std::string withMap = base + "--env-map '" + dir + "/sky.exr' --checkpoint '" + dir + "/c.ckpt' ";
  ASSERT_EQ(test::runFredholm(withMap + "-o '" + dir + "/c.exr' --env-rotate 45").exitCode, 0);
  const auto turned = test::runFredholm(base + "-o '" + dir + "/d.exr' --env-map '" + dir + "/sky.exr' --resume '" +
                                        dir + "/c.ckpt' --env-rotate 46");
  EXPECT_NE(turned.exitCode, 0);
  EXPECT_NE(turned.output.find("another scene, camera or settings"), std::string::npos) << turned.output;

  map.rgb[7] = -1.f;
  writeImage(dir + "/negative.exr", map, {});
  struct Bad {
    std::string args, message;
  };
  for (const Bad& bad :
       std::vector<Bad>{{"--env-map '" + dir + "/missing.exr'", "--env-map '" + dir + "/missing.exr': file not found"},
                        {"--env-map '" + dir + "/sky.png'", "must be an .exr or .hdr"},
                        {"--env-rotate 10", "--env-rotate applies to --env-map"},
                        {"--env-scale 2", "--env-scale applies to --env-map"},
                        {"--env 1,1,1 --env-map '" + dir + "/sky.exr'", "pick one"},
                        {"--env-map '" + dir + "/sky.exr' --env-scale -1", "--env-scale must be"},
                        {"--env-map '" + dir + "/sky.exr' --env-rotate nan", "--env-rotate"},
                        // A map's texels up to 3.75: scaled by 1e38, texel (14, 0)'s 3.5 is the first past float.
                        {"--env-map '" + dir + "/sky.exr' --env-scale 1e38",
                         "sky.exr: texel (14, 0) is past the float range once multiplied by --env-scale 1e+38"},
                        {"--env-map '" + dir + "/negative.exr'", "negative.exr: texel (2, 0) holds a negative"}}) {
    const auto r = test::runFredholm(base + "-o '" + dir + "/bad.exr' " + bad.args);
    EXPECT_NE(r.exitCode, 0) << bad.args;
    EXPECT_NE(r.output.find("fredholm: error: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(bad.message), std::string::npos) << bad.args << "\n" << r.output;
  }
}

}  // namespace
}  // namespace fh
