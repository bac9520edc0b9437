// The bench's scenes.
#include "bench/bench_scenes.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "base/error.h"
#include "base/vec.h"
#include "scene/scene_loader.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// About 1.1M triangles: the bunny-in-a-box scene plus 15 smaller, rotated copies of the
// bunny on a 4x4 grid over the floor.
Scene bunnyCrowd(const std::string& dir) {
  Scene scene = loadScene(dir + "/bunny/CornellBox-Bunny.obj");
  int bunny = -1;
  for (size_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == "bunny") bunny = int(m);
  if (bunny < 0) throw Error("bunny/CornellBox-Bunny.mtl has no 'bunny' material");
  std::vector<size_t> tris;
  Vec3f lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t t = 0; t < scene.triangleCount(); ++t)
    if (scene.triangleMaterial[t] == bunny) {
      tris.push_back(t);
      for (int k = 0; k < 3; ++k) {
        lo = minv(lo, scene.corner(t, k));
        hi = maxv(hi, scene.corner(t, k));
      }
    }
  const float3 center{(lo[0] + hi[0]) * 0.5f, lo[1], (lo[2] + hi[2]) * 0.5f};
  int copy = 0;
  for (int gz = 0; gz < 4; ++gz)
    for (int gx = 0; gx < 4; ++gx) {
      if (gx == 1 && gz == 2) continue;  // roughly where the original sits
      const float angle = 0.7f * float(++copy), cs = std::cos(angle), sn = std::sin(angle), scale = 0.4f;
      const float3 at{-0.75f + 0.5f * float(gx), 0.f, -0.75f + 0.5f * float(gz)};
      for (size_t t : tris) {
        for (int k = 0; k < 3; ++k) {
          const float3 p = (scene.corner(t, k) - center) * scale;
          const float3 q{cs * p[0] + sn * p[2] + at[0], p[1] + at[1], -sn * p[0] + cs * p[2] + at[2]};
          scene.indices.push_back(unsigned(scene.vertexCount()));
          scene.positions.insert(scene.positions.end(), q.begin(), q.end());
        }
        scene.triangleMaterial.push_back(bunny);
      }
    }
  scene.sourcePath = "bunnies-1m (generated)";
  return scene;
}

}  // namespace

// A scene without emitters (Sponza) gets a stand-in light so shadow rays can be timed: a
// quad over the middle half of the scene's top, facing down.
void addBenchLightIfNone(Scene& scene) {
  if (!scene.lights.empty()) return;
  Vec3f lo, hi;
  scene.bounds(lo, hi);
  const float3 c = (lo + hi) * 0.5f, e = (hi - lo) * 0.25f;
  const float y = hi[1];
  const unsigned base = unsigned(scene.vertexCount());
  for (const float3& p : {float3{c[0] - e[0], y, c[2] - e[2]}, float3{c[0] + e[0], y, c[2] - e[2]},
                          float3{c[0] + e[0], y, c[2] + e[2]}, float3{c[0] - e[0], y, c[2] + e[2]}})
    scene.positions.insert(scene.positions.end(), p.begin(), p.end());
  Material light;
  light.name = "bench-light";
  light.ke = {1.f, 1.f, 1.f};
  scene.materials.push_back(light);
  const int m = int(scene.materials.size() - 1);
  // Counter-clockwise seen from below: the front faces down.
  for (const auto& tri : {std::array<unsigned, 3>{0, 1, 2}, std::array<unsigned, 3>{0, 2, 3}}) {
    for (unsigned k : tri) scene.indices.push_back(base + k);
    scene.triangleMaterial.push_back(m);
    const size_t t = scene.triangleCount() - 1;
    const float area = 0.5f * length(cross(scene.corner(t, 1) - scene.corner(t, 0), scene.corner(t, 2) - scene.corner(t, 0)));
    scene.lights.push_back({unsigned(t), area, {area, area, area}});
  }
}

Scene benchScene(const std::string& spec, std::string& name) {
  const std::string dir = sharedScenesDir();
  auto shared = [&](const std::string& rel) {
    const std::string path = dir + "/" + rel;
    if (!fs::exists(path)) throw Error("bench scene '" + spec + "' needs " + path + " (set FREDHOLM_SCENES)");
    return path;
  };
  name = spec;
  if (spec == "cornell") return loadDefaultScene();
  if (spec == "bunny-box") return loadScene(shared("bunny/CornellBox-Bunny.obj"));
  if (spec == "sponza") return loadScene(shared("sponza/sponza.obj"));
  if (spec == "bunnies-1m") {
    shared("bunny/CornellBox-Bunny.obj");
    return bunnyCrowd(dir);
  }
  name = fs::path(spec).stem().string();
  return loadScene(spec);
}

std::string sharedScenesDir() {
  if (const char* env = std::getenv("FREDHOLM_SCENES"); env && *env) return env;
  return FREDHOLM_SHARED_SCENES_DIR;
}

}  // namespace fh
