// Several devices, one render: a shared pass pool and an in-order merge.
#include "multi_device.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "ray_caster.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;

// The passes of one render, handed out to devices and merged back in pass order.
class PassPool {
 public:
  PassPool(uint32_t passes, size_t pixels, int devices, const RenderSettings& s)
      : total_(passes), pixels_(pixels), settings_(s), outstanding_(size_t(devices)), done_(size_t(devices), 0),
        sum_(pixels * 4, 0.0), sumSq_(pixels * 4, 0.0), progress_(s.progress), start_(Clock::now()) {}

  // The next pass for `device`. When none is left but other devices still have passes in
  // flight, a device with none of its own waits: if one of them fails, its passes come
  // back here and must find a device still running. (A device with passes of its own
  // never waits; it asks again after its next batch.)
  bool take(int device, uint32_t& pass) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (!requeued_.empty()) {
        pass = requeued_.front();
        requeued_.pop_front();
        break;
      }
      const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
      if (next_ < total_ && !(settings_.seconds > 0.0 && elapsed >= settings_.seconds)) {
        pass = next_++;
        break;
      }
      if (!outstanding_[size_t(device)].empty() || !anyOutstanding()) return false;
      changed_.wait(lock);
    }
    outstanding_[size_t(device)].insert(pass);
    return true;
  }

  void done(int device, uint32_t pass, std::vector<float>& samples) {
    std::lock_guard<std::mutex> lock(mutex_);
    outstanding_[size_t(device)].erase(pass);
    changed_.notify_all();
    ++done_[size_t(device)];
    pending_[pass].swap(samples);
    mergeInOrder();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    progress_.update(merged_ * pixels_, settings_.seconds > 0.0 ? 0 : uint64_t(total_) * pixels_, elapsed,
                     settings_.seconds > 0.0 ? std::min(1.0, elapsed / settings_.seconds) : 0.0);
  }

  // A failed device's passes in flight go back to the pool for the others.
  void fail(int device) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (uint32_t pass : outstanding_[size_t(device)]) requeued_.push_back(pass);
    outstanding_[size_t(device)].clear();
    changed_.notify_all();
  }

  uint64_t passesDone(int device) const { return done_[size_t(device)]; }

  // Merges whatever finished, skipping passes nobody could render (all devices failed).
  Film film(int width, int height, bool& complete) {
    std::lock_guard<std::mutex> lock(mutex_);
    complete = pending_.empty() && requeued_.empty();
    while (!pending_.empty()) {
      add(pending_.begin()->second);
      pending_.erase(pending_.begin());
    }
    Film f;
    f.width = width;
    f.height = height;
    f.sum.assign(sum_.begin(), sum_.end());
    f.sumSq.assign(sumSq_.begin(), sumSq_.end());
    progress_.finish(merged_ * pixels_, std::chrono::duration<double>(Clock::now() - start_).count());
    return f;
  }

  uint64_t merged() const { return merged_; }

 private:
  void add(const std::vector<float>& samples) {
    for (size_t i = 0; i < pixels_; ++i)
      for (size_t c = 0; c < 4; ++c) {
        const double v = samples[4 * i + c];
        sum_[4 * i + c] += v;
        if (c < 3) sumSq_[4 * i + c] += v * v;
      }
    ++merged_;
  }

  bool anyOutstanding() const {
    for (const auto& o : outstanding_)
      if (!o.empty()) return true;
    return false;
  }

  void mergeInOrder() {
    for (auto it = pending_.find(nextToMerge_); it != pending_.end(); it = pending_.find(nextToMerge_)) {
      add(it->second);
      pending_.erase(it);
      ++nextToMerge_;
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;  // passes finished, or came back from a failed device
  const uint32_t total_;
  const size_t pixels_;
  const RenderSettings settings_;
  uint32_t next_ = 0, nextToMerge_ = 0;
  uint64_t merged_ = 0;
  std::deque<uint32_t> requeued_;
  std::vector<std::set<uint32_t>> outstanding_;
  std::vector<uint64_t> done_;
  std::map<uint32_t, std::vector<float>> pending_;
  std::vector<double> sum_, sumSq_;
  Progress progress_;
  Clock::time_point start_;
};

// One device's view of the pool; can simulate the device failing (FREDHOLM_FAIL_DEVICE).
class DeviceSource : public PassSource {
 public:
  DeviceSource(PassPool& pool, int device, long failAfter) : pool_(pool), device_(device), failAfter_(failAfter) {}
  bool take(uint32_t& pass) override { return pool_.take(device_, pass); }
  void done(uint32_t pass, std::vector<float>& samples) override {
    if (failAfter_ >= 0 && long(pool_.passesDone(device_)) >= failAfter_)
      throw Error("simulated failure (FREDHOLM_FAIL_DEVICE) on finishing pass " + std::to_string(pass));
    pool_.done(device_, pass, samples);
  }

 private:
  PassPool& pool_;
  int device_;
  long failAfter_;
};

// FREDHOLM_FAIL_DEVICE=i:n: device i fails when it finishes its (n+1)-th pass.
long simulatedFailure(int device) {
  const char* spec = std::getenv("FREDHOLM_FAIL_DEVICE");
  if (!spec || !*spec) return -1;
  const std::string s(spec);
  const auto colon = s.find(':');
  if (colon == std::string::npos || std::stoi(s.substr(0, colon)) != device) return -1;
  return std::stol(s.substr(colon + 1));
}

}  // namespace

MultiDeviceResult renderOnDevices(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                                  const Camera& camera, const RenderSettings& settings) {
  const size_t pixels = size_t(settings.width) * size_t(settings.height);
  PassPool pool(uint32_t(std::max(1, settings.spp)), pixels, int(devices.size()), settings);
  MultiDeviceResult result;
  result.stats.devices.resize(devices.size());
  std::vector<RenderStats> perDevice(devices.size());
  const auto start = Clock::now();

  // Every device builds its program and uploads the scene first; the passes are handed out
  // once all are ready (or failed), so a device that compiles slowly is not left without
  // work by one that compiled fast.
  std::mutex readyMutex;
  std::condition_variable readyChanged;
  size_t settled = 0;
  auto settle = [&] {
    std::unique_lock<std::mutex> lock(readyMutex);
    ++settled;
    readyChanged.notify_all();
    readyChanged.wait(lock, [&] { return settled == devices.size(); });
  };

  std::vector<Clock::time_point> ends(devices.size());
  std::vector<std::thread> threads;
  for (size_t i = 0; i < devices.size(); ++i) {
    threads.emplace_back([&, i] {
      auto& share = result.stats.devices[i];
      share.name = devices[i].name;
      bool settledHere = false;
      auto begin = Clock::now();
      try {
        DeviceContext dc(devices[i]);
        RenderSettings s = settings;
        s.progress = false;
        PathTracer tracer(dc, scene, bvh, camera, s);
        settledHere = true;
        settle();
        begin = Clock::now();
        DeviceSource source(pool, int(i), simulatedFailure(int(i)));
        tracer.renderPasses(source);
        perDevice[i] = tracer.stats();
      } catch (const std::exception& e) {
        share.error = e.what();
        pool.fail(int(i));
        if (!settledHere) settle();
      }
      ends[i] = Clock::now();
      share.busySeconds = std::chrono::duration<double>(ends[i] - begin).count();
    });
  }
  for (auto& t : threads) t.join();

  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.film = pool.film(settings.width, settings.height, result.complete);
  RenderStats& st = result.stats;
  st.device = devices.front().name;
  st.seconds = seconds;
  st.samples = pool.merged() * pixels;
  for (size_t i = 0; i < devices.size(); ++i) {
    auto& share = st.devices[i];
    share.samples = pool.passesDone(int(i)) * pixels;
    // Idle: waiting at the end for the last device to finish.
    share.idleSeconds = std::chrono::duration<double>(*std::max_element(ends.begin(), ends.end()) - ends[i]).count();
    const RenderStats& d = perDevice[i];
    st.nonfinite += d.nonfinite;
    st.cameraRays += d.cameraRays;
    st.bounceRays += d.bounceRays;
    st.shadowRays += d.shadowRays;
    st.iterations += d.iterations;
    st.wavefront += d.wavefront;
    for (const auto& [name, t] : d.kernelSeconds) st.kernelSeconds[name] += t;
  }
  return result;
}

}  // namespace fh
