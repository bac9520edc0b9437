// What a render measured: samples and time, rays per kind, queue occupancy, time per
// pipeline stage, and each device's share. `fredholm render --stats` writes it as JSON.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/settings.h"

namespace fh {

struct RenderStats {
  // One per device asked to render, in --device order.
  struct DeviceShare {
    std::string name;
    uint64_t samples = 0;
    size_t wavefront = 0;
    std::string strategy;  // how the device ran the stages (settings.h)
    double busySeconds = 0.0, idleSeconds = 0.0;
    std::string error;  // why the device stopped early, if it did
  };
  std::vector<DeviceShare> devices;
  // One per process when several shared the render (host/distributed), by rank; on rank 0.
  struct RankShare {
    int rank = 0;
    uint64_t passes = 0;
    double seconds = 0.0, idleSeconds = 0.0;  // rendering; waiting for the last rank to finish
    uint64_t bytesSent = 0;                   // the film and the pass requests
    std::string devices;
  };
  std::vector<RankShare> ranks;
  uint64_t samples = 0, nonfinite = 0;
  double seconds = 0.0;
  // Samples a second after each device's first pass (which carries the kernels' build),
  // summed over the devices (0: none finished two passes), and when the first pass ended.
  double steadySamplesPerSecond = 0.0, firstPassSeconds = 0.0;
  uint64_t cameraRays = 0, bounceRays = 0, shadowRays = 0;
  size_t wavefront = 0;  // paths in flight, over all devices
  uint64_t iterations = 0;
  uint64_t queuedRays = 0, slotIterations = 0;  // rays per iteration, and wavefront size, summed
  double meanQueueOccupancy() const { return slotIterations ? double(queuedRays) / double(slotIterations) : 0.0; }
  std::map<std::string, double> stageSeconds;  // by kernel name, summed over devices

  // Adds one device's counts (rays, iterations, stage times; not samples or seconds).
  void add(const RenderStats& device);
  // The devices that rendered at least one pass, comma-separated.
  std::string contributors() const;
};

// The --stats JSON: per-stage time, rays per kind, queue occupancy, samples, seconds,
// samples_per_second, nonfinite_samples and devices ({name, samples, share, ...}).
std::string statsJson(const RenderStats& stats, const RenderSettings& settings);

}  // namespace fh
