// The BVH builder survives any finite scene: random scenes whose coordinates span 1e-45 to
// FLT_MAX (triangles a few 1e-37 wide beside a floor, scenes at 1e38 with rays from inside,
// denormals, coordinates at FLT_MAX, zero-area triangles, every triangle at one point, every
// centroid at one point, triangles spanning the whole float range), each built without
// spatial splits, with the default budget and with a large one. Every build must satisfy
// the structural invariants of tests/fuzz/bvh_check.h (shared with the fuzz target
// fuzz_bvh_build), and every ray's closest hit found through the tree must be the one a
// brute-force pass over all triangles finds (the same double-precision test, so any
// difference is a triangle the tree lost). The device kernels trace in float, which
// overflows at these scales, so the tree is traversed here on the host (bvh_check.h).
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "base/error.h"
#include "fuzz/bvh_check.h"
#include "scene/scene.h"

namespace fh {
namespace {

using Coords = std::vector<float>;  // nine per triangle

Scene sceneOf(const Coords& xyz) {
  Scene s;
  s.positions = xyz;
  for (unsigned i = 0; i < xyz.size() / 3; ++i) s.indices.push_back(i);
  s.triangleMaterial.assign(xyz.size() / 9, 0);
  s.materials.push_back(Material{});
  return s;
}

// Doubles to floats clamped to the finite range (the scenes are finite by construction).
float toFloat(double x) { return float(std::clamp(x, -double(FLT_MAX), double(FLT_MAX))); }

void addTriangle(Coords& c, const std::array<double, 9>& v) {
  for (double x : v) c.push_back(toFloat(x));
}

double uniform(std::mt19937& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

// A magnitude 10^e with e uniform in [lo, hi], of either sign.
double logUniform(std::mt19937& rng, double lo, double hi) {
  const double m = std::pow(10.0, uniform(rng, lo, hi));
  return rng() & 1 ? m : -m;
}

// A triangle around `center` whose corners lie within `size` of it.
void triangleAround(Coords& c, std::mt19937& rng, const std::array<double, 3>& center, double size) {
  std::array<double, 9> v;
  for (int k = 0; k < 9; ++k) v[size_t(k)] = center[size_t(k % 3)] + size * uniform(rng, -1.0, 1.0);
  addTriangle(c, v);
}

// ---- The scenes ----

// Bug report (a): triangles a few 1e-37 wide near the origin, above a normal-size floor.
Coords tinyBesideFloor(std::mt19937& rng) {
  Coords c;
  addTriangle(c, {-10, -1, -10, 10, -1, -10, 10, -1, 10});
  addTriangle(c, {-10, -1, -10, 10, -1, 10, -10, -1, 10});
  for (int i = 0; i < 300; ++i)
    triangleAround(c, rng, {uniform(rng, -3e-37, 3e-37), uniform(rng, -3e-37, 3e-37), uniform(rng, -3e-37, 3e-37)},
                   3e-37);
  return c;
}

// Bug report (b): a scene of ~3e38 (rays start inside it).
Coords huge(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 300; ++i) triangleAround(c, rng, {0, 0, 0}, 3e38);
  return c;
}

// Small triangles spread over the float range, and big ones among them.
Coords hugeAndSmall(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 200; ++i)
    triangleAround(c, rng, {uniform(rng, -3e38, 3e38), uniform(rng, -3e38, 3e38), uniform(rng, -3e38, 3e38)}, 1.0);
  for (int i = 0; i < 50; ++i) triangleAround(c, rng, {0, 0, 0}, 3e38);
  return c;
}

Coords allTiny(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 300; ++i) triangleAround(c, rng, {0, 0, 0}, 1e-37);
  return c;
}

// Every coordinate a denormal (or zero).
Coords allDenormal(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 300; ++i) triangleAround(c, rng, {0, 0, 0}, 1e-41);
  return c;
}

// Centres and sizes log-uniform from 1e-38 to 1e38: every scale beside every other.
Coords everyScale(std::mt19937& rng, int triangles) {
  Coords c;
  for (int i = 0; i < triangles; ++i)
    triangleAround(c, rng, {logUniform(rng, -38, 38), logUniform(rng, -38, 38), logUniform(rng, -38, 38)},
                   std::fabs(logUniform(rng, -38, 38)));
  return c;
}

// Zero-area triangles (three equal corners, or on a line) among ordinary ones, at every scale.
Coords degenerate(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 300; ++i) {
    const double s = std::fabs(logUniform(rng, -38, 37));
    const double x = logUniform(rng, -38, 37), y = logUniform(rng, -38, 37), z = logUniform(rng, -38, 37);
    const double dx = s * uniform(rng, -1, 1), dy = s * uniform(rng, -1, 1), dz = s * uniform(rng, -1, 1);
    switch (i % 3) {
      case 0: addTriangle(c, {x, y, z, x, y, z, x, y, z}); break;
      case 1: addTriangle(c, {x, y, z, x + dx, y + dy, z + dz, x + 2 * dx, y + 2 * dy, z + 2 * dz}); break;
      default: triangleAround(c, rng, {x, y, z}, s);
    }
  }
  return c;
}

// Every corner of every triangle at one point.
Coords onePoint(std::mt19937&) {
  Coords c;
  for (int i = 0; i < 100; ++i) addTriangle(c, {1e-30, 7, -3e38, 1e-30, 7, -3e38, 1e-30, 7, -3e38});
  return c;
}

// Every triangle's box centred on the origin, sizes from 1e-38 to 1e38: one centroid.
Coords oneCentroid(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 200; ++i) {
    const double s = std::fabs(logUniform(rng, -38, 38));
    addTriangle(c, {-s, -s, -s, s, 0, s, 0, s, 0});
  }
  return c;
}

// Corners at and near +-FLT_MAX.
Coords nearFltMax(std::mt19937& rng) {
  Coords c;
  const double big[] = {FLT_MAX, std::nextafter(FLT_MAX, 0.f), 0.75 * FLT_MAX, 0.5 * FLT_MAX};
  for (int i = 0; i < 300; ++i) {
    std::array<double, 9> v;
    for (double& x : v) x = (rng() & 1 ? 1 : -1) * (rng() % 3 ? big[rng() % 4] : uniform(rng, 0.5, 1.0) * FLT_MAX);
    addTriangle(c, v);
  }
  return c;
}

// Long triangles from -FLT_MAX to FLT_MAX over small ones: spatial splits cut edges that
// cross the whole float range.
Coords spanning(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 100; ++i) {
    const double y = uniform(rng, -1e30, 1e30), z = uniform(rng, -1e30, 1e30);
    addTriangle(c, {-FLT_MAX, y, z, FLT_MAX, y + uniform(rng, 0, 1e30), z, uniform(rng, -1, 1), y, z + 1e30});
  }
  for (int i = 0; i < 100; ++i) triangleAround(c, rng, {0, 0, 0}, 1e30);
  return c;
}

Coords ordinary(std::mt19937& rng) {
  Coords c;
  for (int i = 0; i < 500; ++i) triangleAround(c, rng, {uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1)}, 0.05);
  return c;
}

Coords twoTriangles(std::mt19937& rng) {
  Coords c;
  triangleAround(c, rng, {0, 0, 0}, 1e-38);
  triangleAround(c, rng, {0, 0, 0}, 1e38);
  return c;
}

Coords oneTriangle(std::mt19937& rng) {
  Coords c;
  triangleAround(c, rng, {1, 2, 3}, 1);
  return c;
}

// ---- Rays ----

struct Ray {
  double org[3], dir[3];
};

std::array<double, 3> pointOn(const Scene& s, size_t t, std::mt19937& rng) {
  const double su = std::sqrt(uniform(rng, 0, 1)), b1 = su * uniform(rng, 0, 1), b2 = 1 - su;
  std::array<double, 3> p;
  for (size_t k = 0; k < 3; ++k)
    p[k] = double(s.corner(t, 0)[k]) * (1 - b1 - b2) + double(s.corner(t, 1)[k]) * b1 + double(s.corner(t, 2)[k]) * b2;
  return p;
}

// Origins in the scene's box (inside it), near a triangle's corner, or anywhere at any scale;
// directions at a point of a triangle (most hit) or at random. Origins are floats, as a
// renderer's are.
std::vector<Ray> rays(const Scene& s, size_t count, std::mt19937& rng) {
  Vec3f lo{FLT_MAX, FLT_MAX, FLT_MAX}, hi{-FLT_MAX, -FLT_MAX, -FLT_MAX};
  for (size_t i = 0; i < s.vertexCount(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], s.positions[3 * i + k]);
      hi[k] = std::max(hi[k], s.positions[3 * i + k]);
    }
  std::uniform_int_distribution<size_t> pick(0, s.triangleCount() - 1);
  std::vector<Ray> out;
  while (out.size() < count) {
    Ray r;
    const unsigned kind = unsigned(rng() % 3);
    for (size_t k = 0; k < 3; ++k) {
      double o;
      if (kind == 0) o = uniform(rng, lo[k], hi[k]);
      else if (kind == 1) o = s.corner(pick(rng), 0)[k] + logUniform(rng, -40, 38);
      else o = logUniform(rng, -38, 38);
      r.org[k] = double(toFloat(o));
    }
    if (rng() % 4) {
      const auto target = pointOn(s, pick(rng), rng);
      for (size_t k = 0; k < 3; ++k) r.dir[k] = target[k] - r.org[k];
    } else {
      for (double& d : r.dir) d = uniform(rng, -1, 1);
    }
    if (r.dir[0] != 0.0 || r.dir[1] != 0.0 || r.dir[2] != 0.0) out.push_back(r);
  }
  return out;
}

// ---- The property ----

struct Case {
  const char* name;
  std::function<Coords(std::mt19937&)> make;
  bool hits;  // some triangle has area: some rays must hit
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class AnyFiniteScene : public ::testing::TestWithParam<Case> {};

// Builds the scene with each split budget, checks the structure and traces rays.
void expectSoundTrees(const Scene& scene, size_t rayCount, bool expectHits, unsigned seed, unsigned threads = 1) {
  std::mt19937 rng(seed);
  const std::vector<Ray> batch = rays(scene, rayCount, rng);
  for (float budget : {0.f, 0.5f, 4.f}) {
    SCOPED_TRACE("spatial split budget " + std::to_string(budget));
    Bvh bvh;
    ASSERT_NO_THROW(bvh = buildBvh(scene, {threads, budget}));
    const std::string broken = bvhcheck::checkBvh(scene, bvh, budget == 0.f);
    ASSERT_EQ(broken, "");
    size_t hits = 0, differ = 0;
    std::string first;
    for (const Ray& r : batch) {
      const bvhcheck::Hit byTree = bvhcheck::closestByTree(scene, bvh, r.org, r.dir);
      const bvhcheck::Hit all = bvhcheck::closestByBruteForce(scene, r.org, r.dir);
      hits += all.triangle >= 0;
      if (byTree != all && differ++ == 0) {
        std::ostringstream s;
        s.precision(9);
        s << "ray org (" << r.org[0] << " " << r.org[1] << " " << r.org[2] << ") dir (" << r.dir[0] << " " << r.dir[1]
          << " " << r.dir[2] << "): tree finds triangle " << byTree.triangle << " at " << byTree.t
          << ", brute force triangle " << all.triangle << " at " << all.t;
        first = s.str();
      }
    }
    EXPECT_EQ(differ, 0u) << differ << " of " << batch.size() << " rays disagree; first: " << first;
    if (expectHits) {
      EXPECT_GT(hits, batch.size() / 20) << "too few rays hit for the test to mean much";
    }
  }
}

TEST_P(AnyFiniteScene, BuildsASoundTreeThatFindsEveryClosestHit) {
  std::mt19937 rng(20240601);
  const Scene scene = sceneOf(GetParam().make(rng));
  expectSoundTrees(scene, 400, GetParam().hits, 7);
}

INSTANTIATE_TEST_SUITE_P(
    Scales, AnyFiniteScene,
    ::testing::Values(Case{"TinyBesideFloor", tinyBesideFloor, true}, Case{"Huge", huge, true},
                      Case{"HugeAndSmall", hugeAndSmall, true}, Case{"AllTiny", allTiny, true},
                      Case{"AllDenormal", allDenormal, true},
                      Case{"EveryScale", [](std::mt19937& rng) { return everyScale(rng, 400); }, true},
                      Case{"Degenerate", degenerate, true}, Case{"OnePoint", onePoint, false},
                      Case{"OneCentroid", oneCentroid, true}, Case{"NearFltMax", nearFltMax, true},
                      Case{"Spanning", spanning, true}, Case{"Ordinary", ordinary, true},
                      Case{"TwoTriangles", twoTriangles, true}, Case{"OneTriangle", oneTriangle, true}),
    [](const ::testing::TestParamInfo<Case>& c) { return std::string(c.param.name); });

// Big enough for subtrees built on threads of their own (bvh.cpp: kParallelTriangles): the
// same tree on any thread count, and a sound one.
TEST(AnyFiniteSceneBuild, EveryScaleOnThreads) {
  std::mt19937 rng(99);
  const Scene scene = sceneOf(everyScale(rng, 40000));
  const Bvh serial = buildBvh(scene, {1});
  const Bvh parallel = buildBvh(scene, {3});
  EXPECT_EQ(parallel.order, serial.order);
  ASSERT_EQ(parallel.nodes.size(), serial.nodes.size());
  ASSERT_EQ(parallel.blocks.size(), serial.blocks.size());
  EXPECT_EQ(std::memcmp(parallel.nodes.data(), serial.nodes.data(), serial.nodes.size() * sizeof(gpu::Bvh8Node)), 0);
  EXPECT_EQ(bvhcheck::checkBvh(scene, parallel, false), "");
  expectSoundTrees(scene, 40, true, 3, 3);
}

// What cannot be built says so in one line.
TEST(AnyFiniteSceneBuild, NonFiniteAndEmptyScenesAreErrors) {
  for (float bad : {INFINITY, -INFINITY, NAN}) {
    Coords c = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    c[13] = bad;
    try {
      buildBvh(sceneOf(c));
      ADD_FAILURE() << bad << " built";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("triangle 1 has a non-finite vertex"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(buildBvh(sceneOf({})), Error);
}

}  // namespace
}  // namespace fh
