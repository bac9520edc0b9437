// The wavefront path tracer: generate -> intersect -> shade -> shadow_connect ->
// accumulate over queues of paths held in structure-of-arrays buffers (path_state.h),
// refilling finished paths with new camera samples so the queues stay full.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "camera.h"
#include "device_scene.h"
#include "image_io.h"
#include "progress.h"

namespace fh {

enum class Method { PT, NEE, MIS };
Method parseMethod(const std::string& name);  // errors name --method
const char* methodName(Method m);

enum class PixelFilter { Box, Gaussian, BlackmanHarris };
PixelFilter parseFilter(const std::string& name);  // errors name --filter
const char* filterName(PixelFilter f);

// The filter's 1D inverse CDF over [-radius, radius], `size` entries (separable filters).
std::vector<float> filterInverseCdf(PixelFilter filter, int size, float* radius);

struct RenderSettings {
  int width = 512, height = 512;
  int spp = 64;          // samples per pixel; with seconds > 0, the most to take
  double seconds = 0.0;  // time budget: stop at the end of the pass running when it is spent
  Method method = Method::MIS;
  int maxDepth = 64;     // bounces; Russian roulette does the real work
  int rrDepth = 3;       // Russian roulette from this bounce on
  unsigned seed = 1;
  std::array<float, 3> env{0.f, 0.f, 0.f};
  PixelFilter filter = PixelFilter::Box;
  size_t wavefront = 0;  // paths in flight; 0: chosen for the device
  bool progress = false;
  bool allFeatures = false;  // compile every material feature, not only the scene's (benchmarks)
};

// Per pixel: the sum of samples (rgb, w: count) and the sum of their squares.
struct Film {
  int width = 0, height = 0;
  std::vector<float> sum, sumSq;
  Image image() const;  // the mean per pixel
  // The variance of the pixel's mean estimate, per channel (sample variance / count).
  std::array<double, 3> varianceOfMean(size_t pixel) const;
  double count(size_t pixel) const { return sum[4 * pixel + 3]; }
};

struct RenderStats {
  // With several devices: each one's share ({name, samples, seconds busy, idle, error}).
  struct DeviceShare {
    std::string name;
    uint64_t samples = 0;
    double busySeconds = 0.0, idleSeconds = 0.0;
    std::string error;  // why the device stopped early, if it did
  };
  std::vector<DeviceShare> devices;
  std::string device;
  uint64_t samples = 0, nonfinite = 0;
  double seconds = 0.0;
  uint64_t cameraRays = 0, bounceRays = 0, shadowRays = 0;
  size_t wavefront = 0;
  uint64_t iterations = 0;
  double meanQueueOccupancy = 0.0;  // rays per iteration / wavefront size
  std::map<std::string, double> kernelSeconds;
};

// The --stats JSON: per-kernel time, rays per kind, queue occupancy, samples, seconds,
// samples_per_second, nonfinite_samples and devices ({name, samples}).
std::string statsJson(const RenderStats& stats, const RenderSettings& settings);

// The path tracer's program for a scene's features, a method and the passes in flight.
ProgramSpec pathTracerProgram(const SceneFeatures& features, Method method, unsigned passSlots,
                              const std::string& traversalOptions);

// The default number of paths in flight: 512k on a GPU, fewer on a CPU, where the
// path state should stay near the caches; never more than two passes of pixels.
size_t defaultWavefront(const DeviceInfo& device, size_t pixels);

// Where a device's passes come from when several devices share a render: take() hands
// out the next global pass (false when none is left), done() receives a finished pass's
// per-pixel samples (rgb, 1 per pixel; pixel-major). Called from the device's thread.
class PassSource {
 public:
  virtual ~PassSource() = default;
  virtual bool take(uint32_t& pass) = 0;
  virtual void done(uint32_t pass, std::vector<float>& samples) = 0;
};

class PathTracer {
 public:
  PathTracer(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera, const RenderSettings& s);
  // Renders passes 0 .. spp-1 (or as many as --time allows) into the device's own film.
  Film render();
  // Renders the passes `source` hands out, returning each to it as soon as it is done.
  void renderPasses(PassSource& source);
  const RenderStats& stats() const { return stats_; }
  unsigned passSlots() const { return passSlots_; }

 private:
  struct Run;
  void enqueueIteration(int current);
  void collectKernelTimes();
  void run(Run& run);
  void timeKernel(const char* name, const cl::Event& event);

  DeviceContext& dc_;
  RenderSettings settings_;
  DeviceScene scene_;
  gpu::RenderParams params_{};
  size_t wavefront_;
  unsigned pixels_;
  unsigned passSlots_;  // passes in flight at most
  std::vector<cl::Buffer> pathState_, shadowRequests_;
  cl::Buffer rayQueue_[2], finishedQueue_, freeList_, counters_, passBuffer_, filmSum_, filmSumSq_, filterTable_,
      passTable_;
  std::vector<uint32_t> passTable_host_;  // global pass of each local pass (stable storage for writes)
  cl::Kernel plan_, generate_, intersect_, shade_, shadowConnect_, accumulatePaths_, finish_, accumulatePass_;
  std::vector<std::pair<const char*, cl::Event>> events_;
  RenderStats stats_;
};

}  // namespace fh
