// The ray-casting benchmark.
#include "bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bvh.h"
#include "error.h"
#include "image_io.h"
#include "ray_workload.h"
#include "scene_loader.h"
#include "vec.h"

namespace fh {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

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

namespace {

Camera benchCamera(const Scene& scene) {
  if (scene.hasCamera) return scene.camera;
  Vec3f lo, hi;
  scene.bounds(lo, hi);
  return frameBounds(lo, hi);
}

struct KernelTiming {
  double wallSeconds = 0.0;    // median of enqueue to finish
  double kernelSeconds = 0.0;  // median of the kernel's profiled execution
};

template <typename Launch>
KernelTiming timeKernel(DeviceContext& dc, int repeats, Launch launchOnce) {
  std::vector<double> wall, kernel;
  for (int r = -1; r < repeats; ++r) {  // r == -1 is the warm-up
    cl::Event event;
    const auto start = Clock::now();
    launchOnce(&event);
    FH_CL(dc.queue.finish());
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (r < 0) continue;
    wall.push_back(seconds);
    cl_ulong t0 = 0, t1 = 0;
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &t0));
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &t1));
    kernel.push_back(double(t1 - t0) * 1e-9);
  }
  return {median(wall), median(kernel)};
}

struct RayKind {
  std::string name;
  RayQueue rays;
  bool occlusion, coherent;
};

}  // namespace

std::string sharedScenesDir() {
  if (const char* env = std::getenv("FREDHOLM_SCENES"); env && *env) return env;
  return FREDHOLM_SHARED_SCENES_DIR;
}

int runBench(const BenchOptions& o) {
  if (!o.jsonPath.empty()) checkOutputFile(o.jsonPath, o.force, "--json");
  if (o.repeats < 1 || o.width < 1 || o.height < 1) throw Error("--repeats/--width/--height must be positive");
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty()) scenes = {"cornell", "bunny-box", "sponza", "bunnies-1m"};

  const DeviceInfo device = selectDevices(listDevices(), o.device).front();
  DeviceContext dc(device);
  std::unique_ptr<ExternalTracer> external = o.external ? o.external() : nullptr;
  std::cout << "device: " << device.name << " (" << device.platformName << ")\n";
  if (external) std::cout << "comparing with " << external->name() << " on " << o.threads << " threads\n";
  std::cout << std::left << std::setw(12) << "scene" << std::right << std::setw(10) << "triangles" << std::setw(9)
            << "kind" << std::setw(9) << "rays" << std::setw(10) << "Mrays/s" << std::setw(10) << "kernel";
  if (external) std::cout << std::setw(10) << "E single" << std::setw(10) << "E stream" << std::setw(8) << "ratio"
                          << std::setw(8) << "agree";
  std::cout << "\n";

  nlohmann::json records = nlohmann::json::array(), sceneInfo = nlohmann::json::array();
  for (const std::string& spec : scenes) {
    std::string name;
    Scene scene = benchScene(spec, name);
    addBenchLightIfNone(scene);
    const Bvh bvh = buildBvh(scene);
    RayCaster caster(dc, bvh);
    RayWorkload work(dc, scene, bvh, caster);
    const double embreeBuild = external ? external->build(scene) : 0.0;

    const RayQueue primary = work.primary(benchCamera(scene), o.width, o.height, 1);
    const cl::Buffer primaryHits = work.closestHits(primary);
    std::vector<RayKind> kinds = {{"primary", primary, false, true},
                                  {"bounce", work.bounce(primary, primaryHits, 2), false, false},
                                  {"shadow", work.shadow(primary, primaryHits, 3), true, false}};
    nlohmann::json info = {{"scene", name},
                           {"triangles", scene.triangleCount()},
                           {"bvh_build_seconds", bvh.stats.buildSeconds},
                           {"bvh_bytes", bvh.bytes()},
                           {"bvh_bytes_per_triangle", double(bvh.bytes()) / double(scene.triangleCount())},
                           {"bvh_wide_nodes", bvh.stats.wideNodes},
                           {"bvh_depth", bvh.stats.depth},
                           {"kernel_compile_seconds", caster.buildInfo().seconds},
                           {"kernel_from_cache", caster.buildInfo().fromCache}};
    if (external) info["embree_build_seconds"] = embreeBuild;
    sceneInfo.push_back(info);

    for (RayKind& kind : kinds) {
      const unsigned n = kind.rays.count;
      if (n == 0) continue;
      cl::Buffer out = allocateBuffer(dc.context, device.device, CL_MEM_READ_WRITE, n * 16ull, "bench hits");
      const KernelTiming timing = timeKernel(dc, o.repeats, [&](cl::Event* e) {
        if (kind.occlusion) caster.intersectAny(kind.rays.org, kind.rays.dir, out, n, e);
        else caster.intersectClosest(kind.rays.org, kind.rays.dir, out, n, e);
      });
      nlohmann::json record = {{"scene", name},
                               {"triangles", scene.triangleCount()},
                               {"ray_kind", kind.name},
                               {"rays", n},
                               {"mrays_per_s", n / timing.wallSeconds * 1e-6},
                               {"kernel_mrays_per_s", n / timing.kernelSeconds * 1e-6}};
      std::cout << std::left << std::setw(12) << name << std::right << std::setw(10) << scene.triangleCount()
                << std::setw(9) << kind.name << std::setw(9) << n << std::fixed << std::setprecision(2)
                << std::setw(10) << n / timing.wallSeconds * 1e-6 << std::setw(10)
                << n / timing.kernelSeconds * 1e-6;
      if (external) {
        const std::vector<float> org = work.readFloat4(kind.rays.org, n), dir = work.readFloat4(kind.rays.dir, n);
        // fredholm's answers, in file-order triangle ids, to check the tracers agree.
        std::vector<int> ours(n);
        if (kind.occlusion) {
          FH_CL(dc.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * 4ull, ours.data()));
        } else {
          const std::vector<float> hits = work.readFloat4(out, n);
          for (unsigned i = 0; i < n; ++i) {
            int t;
            std::memcpy(&t, &hits[4 * i + 3], 4);
            ours[i] = t < 0 ? -1 : int(bvh.order[size_t(t)]);
          }
        }
        double best = 0.0;
        std::vector<int> theirs;
        for (const std::string& api : external->apis()) {
          std::vector<double> seconds;
          for (int r = -1; r < o.repeats; ++r) {
            const double s = external->trace(api, org, dir, kind.occlusion, kind.coherent, o.threads, theirs);
            if (r >= 0) seconds.push_back(s);
          }
          const double mrays = n / median(seconds) * 1e-6;
          record["embree_" + api + "_mrays_per_s"] = mrays;
          best = std::max(best, mrays);
          std::cout << std::setw(10) << mrays;
        }
        size_t agree = 0;
        for (unsigned i = 0; i < n; ++i) agree += ours[i] == theirs[i];
        record["embree_mrays_per_s"] = best;
        record["ratio_to_embree"] = record["mrays_per_s"].get<double>() / best;
        record["agreement_with_embree"] = double(agree) / n;
        std::cout << std::setw(8) << record["ratio_to_embree"].get<double>() << std::setw(7) << std::setprecision(1)
                  << 100.0 * agree / n << "%";
      }
      std::cout << std::defaultfloat << "\n";
      records.push_back(record);
    }
    std::cout << "  " << name << ": BVH " << std::fixed << std::setprecision(3) << bvh.stats.buildSeconds << " s, "
              << std::setprecision(1) << bvh.bytes() / double(1 << 20) << " MiB ("
              << double(bvh.bytes()) / double(scene.triangleCount()) << " B/triangle), depth " << bvh.stats.depth
              << ", kernel build " << std::setprecision(3) << caster.buildInfo().seconds << " s"
              << (caster.buildInfo().fromCache ? " (cached)" : " (compiled)");
    if (external) std::cout << ", Embree build " << embreeBuild << " s";
    std::cout << std::defaultfloat << "\n";
  }
  if (!o.jsonPath.empty()) {
    nlohmann::json doc = {{"device", device.name},
                          {"external", external ? external->name() : ""},
                          {"threads", o.threads},
                          {"primary_rays", o.width * o.height},
                          {"repeats", o.repeats},
                          {"scenes", sceneInfo},
                          {"records", records}};
    std::ofstream out(o.jsonPath);
    if (!out) throw Error("--json '" + o.jsonPath + "': cannot write");
    out << doc.dump(2) << "\n";
    std::cout << "wrote " << o.jsonPath << "\n";
  }
  return 0;
}

}  // namespace fh
