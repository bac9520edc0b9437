// A render: workers on their threads, one pool, one film.
#include "render/render.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "base/test_hooks.h"
#include "render/device_worker.h"
#include "render/light_tracer.h"
#include "render/pass_pool.h"
#include "render/wavefront.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;

// FREDHOLM_FAIL_DEVICE=i:n (base/test_hooks.h): device i fails when it finishes its (n+1)-th pass.
long simulatedFailure(int device) {
  const TestHooks::DeviceFailure& failure = testHooks().failDevice;
  return failure.device == device ? failure.afterPasses : -1;
}

// Every device builds its program and uploads the scene first; passes are handed out
// once all are ready (or failed), so a device that compiles slowly is not left without
// work by one that compiled fast.
class StartLine {
 public:
  explicit StartLine(size_t devices) : devices_(devices) {}
  void arrive() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (++arrived_ == devices_) released_ = Clock::now();
    changed_.notify_all();
    changed_.wait(lock, [&] { return arrived_ == devices_; });
  }
  // When the last device arrived: the render's clock starts there (set-up excluded).
  Clock::time_point released() const { return released_; }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  size_t devices_, arrived_ = 0;
  Clock::time_point released_ = Clock::now();
};

// A device to render on: one set up already, or one to set up on the worker's thread (so
// a device that fails to start fails alone).
struct Device {
  DeviceInfo info;
  DeviceContext* context = nullptr;
};

// One render in progress: the pool, and what each device's worker reports.
class Render {
 public:
  Render(const std::vector<Device>& devices, const Scene& scene, const Bvh& bvh, const Camera& camera,
         const RenderSettings& settings, const RenderLinks& links)
      : devices_(devices),
        scene_(prepareScene(scene, bvh, featuresFor(scene, settings), settings.envMap.get())),
        bvh_(bvh),
        camera_(camera),
        settings_(settings),
        links_(links),
        pool_(settings, links, int(devices.size())),
        startLine_(devices.size()),
        shares_(devices.size()),
        counts_(devices.size()),
        ends_(devices.size()),
        errors_(devices.size()) {}

  RenderResult run() {
    std::vector<std::thread> threads;
    for (size_t i = 0; i < devices_.size(); ++i) threads.emplace_back([this, i] { work(i); });
    for (auto& t : threads) t.join();
    return collect(std::chrono::duration<double>(Clock::now() - startLine_.released()).count());
  }

 private:
  // Device i's worker, on its own thread. A device that fails gives its passes back.
  void work(size_t i) {
    auto& share = shares_[i];
    share.name = devices_[i].info.name;
    bool started = false;
    auto begin = Clock::now();
    try {
      std::unique_ptr<DeviceContext> own;
      DeviceContext& dc =
          devices_[i].context ? *devices_[i].context : *(own = std::make_unique<DeviceContext>(devices_[i].info));
      RenderSettings perDevice = settings_;
      perDevice.progress = false;  // the pool shows the render's progress
      const std::unique_ptr<PassRenderer> pipeline = passRenderer(dc, perDevice);
      share.wavefront = pipeline->wavefront();
      share.strategy = strategyName(pipeline->strategy());
      started = true;
      startLine_.arrive();
      begin = Clock::now();
      DeviceWorker(int(i), *pipeline, pool_, simulatedFailure(int(i))).run(links_);
      if (links_.stopRequested()) pool_.fail(int(i));  // wakes workers waiting for its passes
      FH_CL(dc.queue.finish());
      counts_[i] = pipeline->stats();
    } catch (const std::exception& e) {
      share.error = e.what();
      errors_[i] = std::current_exception();
      pool_.fail(int(i));
      if (!started) startLine_.arrive();
    }
    ends_[i] = Clock::now();
    share.busySeconds = std::chrono::duration<double>(ends_[i] - begin).count();
  }

  // The method's pipeline on one device: paths from the camera, or from the lights.
  std::unique_ptr<PassRenderer> passRenderer(DeviceContext& dc, const RenderSettings& s) const {
    if (tracesLightPaths(s.method)) return std::make_unique<LightTracer>(dc, scene_, bvh_, camera_, s);
    return std::make_unique<WavefrontPipeline>(dc, scene_, bvh_, camera_, s);
  }

  // The film and the totals. Nothing rendered and nothing left to render on: the render
  // failed, for the reason the first device gave (a build error, a buffer too large, ...).
  RenderResult collect(double seconds) {
    uint64_t passes = 0;
    for (size_t i = 0; i < devices_.size(); ++i) passes += pool_.passesDone(int(i));
    if (passes == 0 && !links_.stopRequested() &&
        std::all_of(errors_.begin(), errors_.end(), [](const auto& e) { return e != nullptr; }))
      std::rethrow_exception(errors_.front());
    RenderResult result;
    result.film = pool_.finish(result.complete);
    result.stopped = links_.stopRequested();
    result.warnings = scene_.warnings;
    for (const auto& w : pool_.warnings()) result.warnings.push_back(w);
    RenderStats& st = result.stats;
    st.seconds = seconds;
    st.steadySamplesPerSecond = pool_.samplesPerSecondAfterFirstPass();
    st.firstPassSeconds = pool_.secondsToFirstPass();
    st.devices = shares_;
    const auto lastEnd = *std::max_element(ends_.begin(), ends_.end());
    for (size_t i = 0; i < devices_.size(); ++i) {
      auto& share = st.devices[i];
      share.samples = pool_.samplesDone(int(i));
      share.idleSeconds = std::chrono::duration<double>(lastEnd - ends_[i]).count();  // waiting for the last
      st.samples += share.samples;
      st.add(counts_[i]);
    }
    return result;
  }

  const std::vector<Device>& devices_;
  const PreparedScene scene_;  // once for every device
  const Bvh& bvh_;
  const Camera& camera_;
  const RenderSettings& settings_;
  const RenderLinks& links_;
  PassPool pool_;
  StartLine startLine_;
  std::vector<RenderStats::DeviceShare> shares_;
  std::vector<RenderStats> counts_;
  std::vector<Clock::time_point> ends_;
  std::vector<std::exception_ptr> errors_;
};

}  // namespace

RenderResult render(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh, const Camera& camera,
                    const RenderSettings& settings, const RenderLinks& links) {
  std::vector<Device> list;
  for (const auto& d : devices) list.push_back({d, nullptr});
  return Render(list, scene, bvh, camera, settings, links).run();
}

RenderResult render(DeviceContext& device, const Scene& scene, const Bvh& bvh, const Camera& camera,
                    const RenderSettings& settings, const RenderLinks& links) {
  const std::vector<Device> list = {{device.info, &device}};
  return Render(list, scene, bvh, camera, settings, links).run();
}

}  // namespace fh
