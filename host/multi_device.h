// One render on several OpenCL devices: each runs its own wavefront (sized for it) with
// its own specialized, cached program, and takes passes from a shared counter as it
// finishes them, so fast devices take more (dynamic balancing by measured throughput).
// Finished passes are merged on the host in pass order, in double precision: the image
// is the same estimator as on one device, and deterministic for a seed and device list
// when the devices compute alike.
#pragma once
#include <vector>

#include "devices.h"
#include "path_tracer.h"

namespace fh {

struct MultiDeviceResult {
  Film film;
  RenderStats stats;      // totals, with stats.devices holding each device's share
  bool complete = true;   // false if every device failed before the last pass
};

// A device that fails is reported in stats.devices[i].error; the passes it had taken are
// rendered by the others. If all fail, the result holds the passes finished so far.
// FREDHOLM_FAIL_DEVICE=i:n (tests) makes device i fail on finishing its (n+1)-th pass.
MultiDeviceResult renderOnDevices(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                                  const Camera& camera, const RenderSettings& settings);

}  // namespace fh
