// One render, on one device or several: a pass pool (the source of passes), a device
// worker per device with its own wavefront pipeline (sized and compiled for it), and the
// film the pool merges finished passes into, in pass order and in double precision. One
// device is a pool with one worker, so every render takes the same path and a seed gives
// the same image on one device as on several (when the devices compute alike).
#pragma once
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "device/device_context.h"
#include "device/devices.h"
#include "render/film.h"
#include "render/render_stats.h"
#include "render/settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

struct RenderResult {
  Film film;
  RenderStats stats;      // totals, with stats.devices holding each device's share
  bool complete = true;      // false if a pass was never rendered (every device failed, or stopped)
  bool stopped = false;      // links.stop was set: the film holds the passes finished before it
  std::vector<std::string> warnings;  // from setting the scene up on the devices (unreadable textures)
};

// A device that fails is reported in stats.devices[i].error; the passes it had taken are
// rendered by the others. If all fail, the result holds the passes finished so far.
// FREDHOLM_FAIL_DEVICE=i:n (tests) makes device i fail on finishing its (n+1)-th pass.
RenderResult render(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh, const Camera& camera,
                    const RenderSettings& settings, const RenderLinks& links = {});

// The same on a device already set up (tests render many times on one context).
RenderResult render(DeviceContext& device, const Scene& scene, const Bvh& bvh, const Camera& camera,
                    const RenderSettings& settings, const RenderLinks& links = {});

}  // namespace fh
