// The BVH builder on any finite triangles. An input is one option byte (its low two bits
// pick the spatial split budget: 0, 0.5, 4 or 0.5) and then little-endian floats; the
// non-finite ones are dropped (the loader rejects them) and every nine that remain make a
// triangle. Raw float bits span every scale, denormals to FLT_MAX. Any input must build (or,
// without a triangle, throw fh::Error) a BVH that holds every invariant of bvh_check.h, and
// a few rays must find the same closest hit through it as over all triangles; a violation
// aborts with its description.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "base/error.h"
#include "bvh_check.h"
#include "scene/scene.h"

namespace {

[[noreturn]] void violated(const std::string& what) {
  std::fprintf(stderr, "fuzz_bvh_build: %s\n", what.c_str());
  std::fflush(stderr);
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const float budgets[] = {0.f, 0.5f, 4.f, 0.5f};
  const float budget = budgets[data[0] & 3];
  std::vector<float> coords;
  for (size_t at = 1; at + 4 <= size; at += 4) {
    float x;
    std::memcpy(&x, data + at, 4);
    if (std::isfinite(x)) coords.push_back(x);
  }
  coords.resize(coords.size() / 9 * 9);
  fh::Scene scene;
  scene.positions = coords;
  for (unsigned i = 0; i < coords.size() / 3; ++i) scene.indices.push_back(i);
  scene.triangleMaterial.assign(coords.size() / 9, 0);
  scene.materials.push_back(fh::Material{});

  fh::Bvh bvh;
  try {
    bvh = fh::buildBvh(scene, {1, budget});
  } catch (const fh::Error& e) {
    if (scene.triangleCount() > 0) violated(std::string("finite triangles refused: ") + e.what());
    return 0;
  }
  const std::string broken = fh::bvhcheck::checkBvh(scene, bvh, budget == 0.f);
  if (!broken.empty()) violated(broken);

  // Rays from corners at other triangles' centroids, and from one corner along each axis.
  const size_t n = scene.triangleCount();
  for (size_t k = 0; k < std::min<size_t>(n, 8); ++k) {
    double org[3], dir[3];
    const size_t from = k, to = (7 * k + 3) % n;
    for (size_t a = 0; a < 3; ++a) {
      org[a] = scene.corner(from, 0)[a];
      const double target =
          (double(scene.corner(to, 0)[a]) + double(scene.corner(to, 1)[a]) + double(scene.corner(to, 2)[a])) / 3.0;
      dir[a] = k < 3 ? (a == k ? 1.0 : 0.0) : target - org[a];
    }
    if (dir[0] == 0.0 && dir[1] == 0.0 && dir[2] == 0.0) continue;
    const fh::bvhcheck::Hit byTree = fh::bvhcheck::closestByTree(scene, bvh, org, dir);
    const fh::bvhcheck::Hit all = fh::bvhcheck::closestByBruteForce(scene, org, dir);
    if (byTree != all)
      violated("ray " + std::to_string(k) + ": the tree finds triangle " + std::to_string(byTree.triangle) +
               ", brute force triangle " + std::to_string(all.triangle));
  }
  return 0;
}
