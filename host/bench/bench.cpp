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
#include "base/output_plan.h"
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
  if (scene.hasCamera) return scaledCamera(scene.camera, scene.worldScale);
  Vec3f lo, hi;
  scene.bounds(lo, hi);
  return frameBounds(lo, hi);
}

// One launch: enqueue to finish on the host's clock, and the kernel's profiled time.
struct LaunchTiming {
  double wallSeconds = 0.0, kernelSeconds = 0.0;
};

template <typename Launch>
LaunchTiming timeLaunch(DeviceContext& dc, Launch launchOnce) {
  cl::Event event;
  const auto start = Clock::now();
  launchOnce(&event);
  FH_CL(dc.queue.finish());
  LaunchTiming t;
  t.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  cl_ulong t0 = 0, t1 = 0;
  FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &t0));
  FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &t1));
  t.kernelSeconds = double(t1 - t0) * 1e-9;
  return t;
}

// A repeat of one ray kind takes at least this long per tracer (--repeats of them).
constexpr double kRepeatSeconds = 0.05;

// Each tracer's times, repeat by repeat, and fredholm's speed over the external tracer's
// best within each repeat.
struct KindTimings {
  int passes = 1;  // traces of the rays per repeat and tracer
  std::vector<double> wall, kernel, ratio;
  std::vector<std::vector<double>> external;  // per external API
  // Millions of rays per second over the median repeat of `seconds`, for `rays` per trace.
  double mrays(unsigned rays, const std::vector<double>& seconds) const {
    return double(rays) * passes / median(seconds) * 1e-6;
  }
};

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
    std::vector<int> theirs;
    const KindTimings t = timeInterleaved(dc, caster, work, kind, out, theirs);
    const double mrays = t.mrays(n, t.wall), kernelMrays = t.mrays(n, t.kernel);
    nlohmann::json record = {{"scene", name_},
                             {"device", dc.info.name},
                             {"triangles", scene_.triangleCount()},
                             {"ray_kind", kind.name},
                             {"rays", n},
                             {"mrays_per_s", mrays},
                             {"kernel_mrays_per_s", kernelMrays}};
    std::cout << std::left << std::setw(12) << name_ << std::right << std::setw(4) << deviceIndex << std::setw(10)
              << scene_.triangleCount() << std::setw(9) << kind.name << std::setw(9) << n << std::fixed
              << std::setprecision(2) << std::setw(10) << mrays << std::setw(10) << kernelMrays;
    if (external_) reportExternal(dc, work, kind, out, t, theirs, record);
    std::cout << std::defaultfloat << "\n";
    return record;
  }

  // fredholm and each external API in turn, repeat by repeat (who goes first alternates),
  // so a noisy neighbour slows both alike and each repeat gives a ratio of its own.
  KindTimings timeInterleaved(DeviceContext& dc, RayCaster& caster, RayWorkload& work, const RayKind& kind,
                              const cl::Buffer& out, std::vector<int>& theirs) {
    const unsigned n = kind.rays.count;
    const std::vector<std::string> apis = external_ ? external_->apis() : std::vector<std::string>{};
    std::vector<float> org, dir;
    if (external_) {
      org = work.readFloat4(kind.rays.org, n);
      dir = work.readFloat4(kind.rays.dir, n);
    }
    KindTimings t;
    t.external.resize(apis.size());
    std::vector<double> seconds(apis.size());
    // A repeat traces the rays t.passes times with each tracer (set after the warm-up): enough
    // that the scheduler's hiccups (milliseconds) are small against it on scenes that trace
    // in a few. Each tracer's turn starts with a pass that is not timed: the first pass after
    // a switch finds the caches full of the other's data and the threads placed for the
    // other's, which says nothing of either tracer (bench/RESULTS.md).
    auto traceExternal = [&] {
      for (size_t a = 0; a < apis.size(); ++a) {
        auto once = [&] {
          return external_->trace(apis[a], org, dir, kind.occlusion, kind.coherent, o_.threads, theirs);
        };
        once();
        seconds[a] = 0.0;
        for (int i = 0; i < t.passes; ++i) seconds[a] += once();
      }
    };
    auto traceOurs = [&] {
      auto once = [&] {
        return timeLaunch(dc, [&](cl::Event* e) {
          const RayOrder order = kind.coherent ? RayOrder::Coherent : RayOrder::Incoherent;
          if (kind.occlusion) caster.intersectAny(kind.rays.org, kind.rays.dir, out, n, order, e);
          else caster.intersectClosest(kind.rays.org, kind.rays.dir, out, n, order, e);
        });
      };
      once();
      LaunchTiming sum;
      for (int i = 0; i < t.passes; ++i) {
        const LaunchTiming one = once();
        sum.wallSeconds += one.wallSeconds;
        sum.kernelSeconds += one.kernelSeconds;
      }
      return sum;
    };
    for (int r = -1; r < o_.repeats; ++r) {  // r == -1 is the warm-up
      if (r % 2 != 0) traceExternal();
      const LaunchTiming ours = traceOurs();
      if (r % 2 == 0) traceExternal();
      if (r < 0) {
        t.passes = std::max(1, int(std::ceil(kRepeatSeconds / ours.wallSeconds)));
        continue;
      }
      t.wall.push_back(ours.wallSeconds);
      t.kernel.push_back(ours.kernelSeconds);
      for (size_t a = 0; a < apis.size(); ++a) t.external[a].push_back(seconds[a]);
      if (!apis.empty()) t.ratio.push_back(*std::min_element(seconds.begin(), seconds.end()) / ours.wallSeconds);
    }
    return t;
  }

  // The external tracer's speed per API, the ratio (median over repeats, with its spread),
  // and how often it finds the same triangle (or the same occlusion) as fredholm.
  void reportExternal(DeviceContext& dc, RayWorkload& work, const RayKind& kind, const cl::Buffer& out,
                      const KindTimings& t, const std::vector<int>& theirs, nlohmann::json& record) {
    const unsigned n = kind.rays.count;
    // fredholm's answers, in file-order triangle ids, to check the tracers agree.
    std::vector<int> ours(n);
    if (kind.occlusion) {
      FH_CL(dc.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * 4ull, ours.data()));
    } else {
      const std::vector<float> hits = work.readFloat4(out, n);
      for (unsigned i = 0; i < n; ++i) {
        int tri;
        std::memcpy(&tri, &hits[4 * i + 3], 4);
        ours[i] = tri < 0 ? -1 : int(bvh_.order[size_t(tri)]);
      }
    }
    double best = 0.0;
    const std::vector<std::string> apis = external_->apis();
    for (size_t a = 0; a < apis.size(); ++a) {
      const double mrays = t.mrays(n, t.external[a]);
      record["embree_" + apis[a] + "_mrays_per_s"] = mrays;
      best = std::max(best, mrays);
      std::cout << std::setw(10) << mrays;
    }
    size_t agree = 0;
    for (unsigned i = 0; i < n; ++i) agree += ours[i] == theirs[i];
    const auto [low, high] = std::minmax_element(t.ratio.begin(), t.ratio.end());
    record["embree_mrays_per_s"] = best;
    record["ratio_to_embree"] = median(t.ratio);
    record["ratio_to_embree_min"] = *low;
    record["ratio_to_embree_max"] = *high;
    record["agreement_with_embree"] = double(agree) / n;
    std::ostringstream spread;
    spread << std::fixed << std::setprecision(2) << *low << "-" << *high;
    std::cout << std::setw(8) << median(t.ratio) << std::setw(11) << spread.str() << std::setw(7)
              << std::setprecision(1) << 100.0 * agree / n << "%";
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
                          << std::setw(11) << "spread" << std::setw(8) << "agree";
  std::cout << "\n";
}

nlohmann::json sceneSummary(const std::string& name, const Scene& scene, const Bvh& bvh) {
  std::cout << "  " << name << ": BVH " << std::fixed << std::setprecision(3) << bvh.stats.buildSeconds << " s, SAH "
            << std::setprecision(2) << bvh.stats.sahCost << " (8-wide " << bvh.stats.wideSahCost << "), references "
            << bvh.stats.references << ", "
            << std::setprecision(1)
            << bvh.bytes() / double(1 << 20) << " MiB ("
            << double(bvh.bytes()) / double(scene.triangleCount()) << " B/triangle), depth " << bvh.stats.depth
            << std::defaultfloat << "\n";
  return {{"scene", name},
          {"triangles", scene.triangleCount()},
          {"bvh_build_seconds", bvh.stats.buildSeconds},
          {"bvh_sah_cost", bvh.stats.sahCost},
          {"bvh_wide_sah_cost", bvh.stats.wideSahCost},
          {"bvh_references", bvh.stats.references},
          {"bvh_bytes", bvh.bytes()},
          {"bvh_bytes_per_triangle", double(bvh.bytes()) / double(scene.triangleCount())},
          {"bvh_wide_nodes", bvh.stats.wideNodes},
          {"bvh_depth", bvh.stats.depth}};
}

}  // namespace

// Every scene on every device --device selects, a row per scene, device and ray kind.
int runBench(const BenchOptions& o) {
  OutputPlan plan(o.force);
  if (!o.jsonPath.empty()) plan.add(o.jsonPath, "--json");
  plan.reserve();
  if (o.repeats < 1 || o.width < 1 || o.height < 1) throw Error("--repeats/--width/--height must be positive");
  std::vector<std::string> scenes = o.scenes;
  // By default the scenes this machine has: the built-in box and a generated million
  // triangles, and where FREDHOLM_SCENES names their folder, the larger scenes as well.
  if (scenes.empty())
    scenes = sharedScenesDir().empty() ? std::vector<std::string>{"cornell", "spheres:1e6"}
                                       : std::vector<std::string>{"cornell", "bunny-box", "sponza", "bunnies-1m"};
  for (const std::string& spec : scenes) checkBenchScene(spec);

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
    plan.checkAgainstInputs();
    addBenchLightIfNone(scene);
    const Bvh bvh = buildBvh(scene);
    nlohmann::json info = sceneSummary(name, scene, bvh);
    if (external) {
      info["embree_build_seconds"] = external->build(scene);
      info["embree_bytes"] = external->sceneBytes();
      info["embree_bytes_per_triangle"] = double(external->sceneBytes()) / double(scene.triangleCount());
    }
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
    const std::string written = writeTextAtomically(o.jsonPath, "--json", doc.dump(2) + "\n");
    plan.finish();
    std::cout << "wrote " << written << "\n";
  }
  return 0;
}

}  // namespace fh
