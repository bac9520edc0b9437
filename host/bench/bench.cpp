// The ray-casting benchmark.
#include "bench/bench.h"

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

#include "accel/bvh.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/vec.h"
#include "bench/bench_scenes.h"
#include "bench/ray_workload.h"
#include "image/image_io.h"
#include "scene/scene_loader.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

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

namespace {

// One scene on one device: the BVH uploaded, rays made by fredholm's own kernels, and
// each kind timed here and, with an external tracer, there on the same rays.
class SceneBench {
 public:
  SceneBench(const BenchOptions& o, ExternalTracer* external, const std::string& name, const Scene& scene,
             const Bvh& bvh)
      : o_(o), external_(external), name_(name), scene_(scene), bvh_(bvh) {}

  nlohmann::json run(int deviceIndex, DeviceContext& dc, nlohmann::json& records) {
    RayCaster caster(dc, bvh_);
    RayWorkload work(dc, scene_, bvh_, caster);
    const RayQueue primary = work.primary(benchCamera(scene_), o_.width, o_.height, 1);
    const cl::Buffer primaryHits = work.closestHits(primary);
    std::vector<RayKind> kinds = {{"primary", primary, false, true},
                                  {"bounce", work.bounce(primary, primaryHits, 2), false, false},
                                  {"shadow", work.shadow(primary, primaryHits, 3), true, false}};
    for (RayKind& kind : kinds)
      if (kind.rays.count > 0) records.push_back(timeKind(deviceIndex, dc, caster, work, kind));
    std::cout << "  " << name_ << " on device " << deviceIndex << ": kernel build " << std::fixed
              << std::setprecision(3) << caster.buildInfo().seconds << " s"
              << (caster.buildInfo().fromCache ? " (cached)" : " (compiled)") << std::defaultfloat << "\n";
    return {{"device", dc.info.name},
            {"kernel_compile_seconds", caster.buildInfo().seconds},
            {"kernel_from_cache", caster.buildInfo().fromCache}};
  }

 private:
  nlohmann::json timeKind(int deviceIndex, DeviceContext& dc, RayCaster& caster, RayWorkload& work, RayKind& kind) {
    const unsigned n = kind.rays.count;
    cl::Buffer out = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, n * 16ull, "bench hits");
    const KernelTiming timing = timeKernel(dc, o_.repeats, [&](cl::Event* e) {
      if (kind.occlusion) caster.intersectAny(kind.rays.org, kind.rays.dir, out, n, e);
      else caster.intersectClosest(kind.rays.org, kind.rays.dir, out, n, e);
    });
    nlohmann::json record = {{"scene", name_},
                             {"device", dc.info.name},
                             {"triangles", scene_.triangleCount()},
                             {"ray_kind", kind.name},
                             {"rays", n},
                             {"mrays_per_s", n / timing.wallSeconds * 1e-6},
                             {"kernel_mrays_per_s", n / timing.kernelSeconds * 1e-6}};
    std::cout << std::left << std::setw(12) << name_ << std::right << std::setw(4) << deviceIndex << std::setw(10)
              << scene_.triangleCount() << std::setw(9) << kind.name << std::setw(9) << n << std::fixed
              << std::setprecision(2) << std::setw(10) << n / timing.wallSeconds * 1e-6 << std::setw(10)
              << n / timing.kernelSeconds * 1e-6;
    if (external_) compareWithExternal(dc, work, kind, out, record);
    std::cout << std::defaultfloat << "\n";
    return record;
  }

  // The external tracer on the same rays: its speed per API, and how often it finds the
  // same triangle (or the same occlusion) as fredholm.
  void compareWithExternal(DeviceContext& dc, RayWorkload& work, const RayKind& kind, const cl::Buffer& out,
                           nlohmann::json& record) {
    const unsigned n = kind.rays.count;
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
        ours[i] = t < 0 ? -1 : int(bvh_.order[size_t(t)]);
      }
    }
    double best = 0.0;
    std::vector<int> theirs;
    for (const std::string& api : external_->apis()) {
      std::vector<double> seconds;
      for (int r = -1; r < o_.repeats; ++r) {
        const double s = external_->trace(api, org, dir, kind.occlusion, kind.coherent, o_.threads, theirs);
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

  const BenchOptions& o_;
  ExternalTracer* external_;
  const std::string& name_;
  const Scene& scene_;
  const Bvh& bvh_;
};

void printHeader(const std::vector<DeviceInfo>& devices, const ExternalTracer* external, int threads) {
  for (size_t i = 0; i < devices.size(); ++i)
    std::cout << "device " << i << ": " << devices[i].name << " (" << devices[i].platformName << ")\n";
  if (external) std::cout << "comparing with " << external->name() << " on " << threads << " threads\n";
  std::cout << std::left << std::setw(12) << "scene" << std::right << std::setw(4) << "dev" << std::setw(10)
            << "triangles" << std::setw(9) << "kind" << std::setw(9) << "rays" << std::setw(10) << "Mrays/s"
            << std::setw(10) << "kernel";
  if (external) std::cout << std::setw(10) << "E single" << std::setw(10) << "E stream" << std::setw(8) << "ratio"
                          << std::setw(8) << "agree";
  std::cout << "\n";
}

nlohmann::json sceneSummary(const std::string& name, const Scene& scene, const Bvh& bvh) {
  std::cout << "  " << name << ": BVH " << std::fixed << std::setprecision(3) << bvh.stats.buildSeconds << " s, "
            << std::setprecision(1) << bvh.bytes() / double(1 << 20) << " MiB ("
            << double(bvh.bytes()) / double(scene.triangleCount()) << " B/triangle), depth " << bvh.stats.depth
            << std::defaultfloat << "\n";
  return {{"scene", name},
          {"triangles", scene.triangleCount()},
          {"bvh_build_seconds", bvh.stats.buildSeconds},
          {"bvh_bytes", bvh.bytes()},
          {"bvh_bytes_per_triangle", double(bvh.bytes()) / double(scene.triangleCount())},
          {"bvh_wide_nodes", bvh.stats.wideNodes},
          {"bvh_depth", bvh.stats.depth}};
}

}  // namespace

// Every scene on every device --device selects, a row per scene, device and ray kind.
int runBench(const BenchOptions& o) {
  if (!o.jsonPath.empty()) checkOutputFile(o.jsonPath, o.force, "--json");
  if (o.repeats < 1 || o.width < 1 || o.height < 1) throw Error("--repeats/--width/--height must be positive");
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty()) scenes = {"cornell", "bunny-box", "sponza", "bunnies-1m"};

  const std::vector<DeviceInfo> devices = selectDevices(listDevices(), o.device);
  std::vector<std::unique_ptr<DeviceContext>> contexts;
  nlohmann::json deviceNames = nlohmann::json::array();
  for (const auto& d : devices) {
    contexts.push_back(std::make_unique<DeviceContext>(d));
    deviceNames.push_back(d.name);
  }
  std::unique_ptr<ExternalTracer> external = o.external ? o.external() : nullptr;
  printHeader(devices, external.get(), o.threads);

  nlohmann::json records = nlohmann::json::array(), sceneInfo = nlohmann::json::array();
  for (const std::string& spec : scenes) {
    std::string name;
    Scene scene = benchScene(spec, name);
    addBenchLightIfNone(scene);
    const Bvh bvh = buildBvh(scene);
    nlohmann::json info = sceneSummary(name, scene, bvh);
    if (external) info["embree_build_seconds"] = external->build(scene);
    info["per_device"] = nlohmann::json::array();
    SceneBench bench(o, external.get(), name, scene, bvh);
    for (size_t i = 0; i < contexts.size(); ++i) info["per_device"].push_back(bench.run(int(i), *contexts[i], records));
    sceneInfo.push_back(info);
  }
  if (!o.jsonPath.empty()) {
    nlohmann::json doc = {{"devices", deviceNames},
                          {"external", external ? external->name() : ""},
                          {"threads", o.threads},
                          {"primary_rays", o.width * o.height},
                          {"repeats", o.repeats},
                          {"scenes", sceneInfo},
                          {"records", records}};
    writeTextAtomically(o.jsonPath, "--json", doc.dump(2) + "\n");
    std::cout << "wrote " << o.jsonPath << "\n";
  }
  return 0;
}

}  // namespace fh
