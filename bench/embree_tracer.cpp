// Embree 3 traced over the same ray buffers as fredholm: the single-ray API
// (rtcIntersect1/rtcOccluded1 in a loop) and the stream API (rtcIntersect1M/
// rtcOccluded1M over chunks), on the same number of threads.
#include "embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

namespace fh {
namespace {

constexpr unsigned kChunk = 256;  // rays per work item and per stream call

class EmbreeTracer : public ExternalTracer {
 public:
  EmbreeTracer() : device_(rtcNewDevice("threads=2")) {
    if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeTracer::countBytes, this);
  }
  ~EmbreeTracer() override {
    if (scene_) rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  std::string name() const override { return "Embree " + std::to_string(RTC_VERSION_MAJOR) + "." +
                                              std::to_string(RTC_VERSION_MINOR) + "." +
                                              std::to_string(RTC_VERSION_PATCH); }
  std::vector<std::string> apis() const override { return {"single", "stream"}; }

  double build(const Scene& scene) override {
    const auto start = std::chrono::steady_clock::now();
    if (scene_) rtcReleaseScene(scene_);
    const long long before = allocated_.load();
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                                 RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                                 scene.vertexCount()));
    std::copy(scene.positions.begin(), scene.positions.end(), vertices);
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                                   RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                                   scene.triangleCount()));
    std::copy(scene.indices.begin(), scene.indices.end(), indices);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
    sceneBytes_ = size_t(std::max(0LL, allocated_.load() - before));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  size_t sceneBytes() const override { return sceneBytes_; }

  double trace(const std::string& api, const std::vector<float>& org, const std::vector<float>& dir, bool occlusion,
               bool coherent, int threads, std::vector<int>& triangle) override {
    const size_t n = org.size() / 4;
    triangle.assign(n, -1);
    // Rays are converted to Embree's layout outside the timed region.
    std::vector<RTCRayHit> rays(n);
    for (size_t i = 0; i < n; ++i) {
      RTCRay& r = rays[i].ray;
      r.org_x = org[4 * i];
      r.org_y = org[4 * i + 1];
      r.org_z = org[4 * i + 2];
      r.tnear = org[4 * i + 3];
      r.dir_x = dir[4 * i];
      r.dir_y = dir[4 * i + 1];
      r.dir_z = dir[4 * i + 2];
      r.tfar = dir[4 * i + 3];
      r.time = 0.f;
      r.mask = 0xffffffffu;
      r.id = unsigned(i);
      r.flags = 0;
      rays[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rays[i].hit.primID = RTC_INVALID_GEOMETRY_ID;
    }
    const bool stream = api == "stream";
    std::atomic<size_t> next{0};
    auto worker = [&] {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
      for (size_t first; (first = next.fetch_add(kChunk)) < n;) {
        const unsigned count = unsigned(std::min<size_t>(kChunk, n - first));
        RTCRayHit* chunk = rays.data() + first;
        if (stream) {
          if (occlusion) rtcOccluded1M(scene_, &context, &chunk->ray, count, sizeof(RTCRayHit));
          else rtcIntersect1M(scene_, &context, chunk, count, sizeof(RTCRayHit));
        } else {
          for (unsigned i = 0; i < count; ++i) {
            if (occlusion) rtcOccluded1(scene_, &context, &chunk[i].ray);
            else rtcIntersect1(scene_, &context, &chunk[i]);
          }
        }
      }
    };
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (size_t i = 0; i < n; ++i) {
      if (occlusion) triangle[i] = rays[i].ray.tfar < 0.f ? 1 : 0;  // Embree sets tfar = -inf when occluded
      else triangle[i] = rays[i].hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : int(rays[i].hit.primID);
    }
    return seconds;
  }

 private:
  // Embree reports every allocation and release: the scene's share is what a build adds.
  static bool countBytes(void* self, ssize_t bytes, bool /*post*/) {
    static_cast<EmbreeTracer*>(self)->allocated_ += bytes;
    return true;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::atomic<long long> allocated_{0};
  size_t sceneBytes_ = 0;
};

}  // namespace

std::unique_ptr<ExternalTracer> makeEmbreeTracer() { return std::make_unique<EmbreeTracer>(); }

}  // namespace fh
