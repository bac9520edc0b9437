// The bench's scenes.
#include "bench/bench_scenes.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "base/error.h"
#include "base/vec.h"
#include "scene/icosphere.h"
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

// About `count` triangles for the scaling chart: a floor under a square grid of spheres of
// 1280 triangles each (fewer, finer spheres below that), bumped so no two are alike.
Scene sphereField(size_t count) {
  Scene scene;
  Material grey;
  grey.name = "grey";
  scene.materials.push_back(grey);
  int levels = 3;  // 1280 triangles a sphere
  while (levels > 0 && size_t(20) << (2 * levels) > count) --levels;
  const IndexedMesh sphere = icosphere(levels);
  const size_t perSphere = sphere.faces.size();
  const size_t spheres = std::max<size_t>(1, (count + perSphere / 2) / perSphere);
  const int side = int(std::ceil(std::sqrt(double(spheres))));
  auto add = [&](const float3& p) {
    scene.indices.push_back(unsigned(scene.vertexCount()));
    scene.positions.insert(scene.positions.end(), p.begin(), p.end());
  };
  const float half = float(side);
  for (const auto& tri : {std::array<float3, 3>{float3{-half, 0, -half}, float3{-half, 0, half}, float3{half, 0, half}},
                          std::array<float3, 3>{float3{-half, 0, -half}, float3{half, 0, half}, float3{half, 0, -half}}}) {
    for (const float3& p : tri) add(p);
    scene.triangleMaterial.push_back(0);
  }
  for (size_t i = 0; i < spheres; ++i) {
    const float x = -half + 1.f + 2.f * float(i % size_t(side)), z = -half + 1.f + 2.f * float(i / size_t(side));
    const float radius = 0.6f + 0.3f * std::sin(1.7f * float(i));
    for (const auto& face : sphere.faces)
      for (unsigned k : face) {
        const float3& c = sphere.vertices[k];
        const float bump = 1.f + 0.1f * std::sin(7.f * c[0] + float(i)) * std::cos(5.f * c[2]);
        add(float3{x, radius, z} + c * (radius * bump));
      }
    scene.triangleMaterial.insert(scene.triangleMaterial.end(), perSphere, 0);
  }
  scene.camera.eye = {0.f, 0.9f * half + 2.f, 1.6f * half + 2.f};
  scene.camera.target = {0.f, 0.f, 0.f};
  scene.hasCamera = true;
  scene.sourcePath = "spheres:" + std::to_string(count) + " (generated)";
  return scene;
}

// The shared scene file a named bench scene is read from (bunnies-1m places copies of the
// bunny), or "" for one that is built in, generated or a path of the user's.
std::string sharedFileOf(const std::string& spec) {
  if (spec == "bunny-box" || spec == "bunnies-1m") return "bunny/CornellBox-Bunny.obj";
  if (spec == "sponza") return "sponza/sponza.obj";
  return "";
}

bool isSphereField(const std::string& spec) { return spec.rfind("spheres:", 0) == 0; }

size_t sphereFieldTriangles(const std::string& spec) {
  char* end = nullptr;
  const double count = std::strtod(spec.c_str() + 8, &end);
  if (end == spec.c_str() + 8 || *end || !(count >= 1) || count > 1e8)
    throw Error("bench scene '" + spec + "': spheres:N takes a triangle count from 1 to 1e8 (e.g. spheres:1e6)");
  return size_t(count);
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

void checkBenchScene(const std::string& spec) {
  if (spec == "cornell") return;
  if (isSphereField(spec)) {
    sphereFieldTriangles(spec);
    return;
  }
  if (const std::string rel = sharedFileOf(spec); !rel.empty()) {
    const std::string dir = sharedScenesDir();
    if (dir.empty())
      throw Error("bench scene '" + spec + "' needs FREDHOLM_SCENES, the folder that holds " + rel);
    const std::string path = dir + "/" + rel;
    if (!fs::exists(path)) throw Error("bench scene '" + spec + "' needs " + path + " (set FREDHOLM_SCENES)");
    return;
  }
  if (!fs::exists(spec))
    throw Error("bench scene '" + spec + "': no such scene (use cornell, bunny-box, sponza, bunnies-1m, spheres:N or an OBJ path)");
}

Scene benchScene(const std::string& spec, std::string& name) {
  checkBenchScene(spec);
  name = spec;
  if (spec == "cornell") return loadDefaultScene();
  if (spec == "bunny-box" || spec == "sponza") return loadScene(sharedScenesDir() + "/" + sharedFileOf(spec));
  if (spec == "bunnies-1m") return bunnyCrowd(sharedScenesDir());
  if (isSphereField(spec)) return sphereField(sphereFieldTriangles(spec));
  name = fs::path(spec).stem().string();
  return loadScene(spec);
}

std::string sharedScenesDir() {
  const char* env = std::getenv("FREDHOLM_SCENES");
  return env ? env : "";
}

}  // namespace fh
