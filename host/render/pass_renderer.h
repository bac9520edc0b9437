// What a device worker (render/device_worker.h) drives: a method's pipeline on one device,
// rendering the passes it is granted into pass buffers and handing each back once complete.
// The path tracer's wavefront (render/wavefront.h) and the light tracer
// (render/light_tracer.h) are the two.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "render/pass_source.h"
#include "render/render_stats.h"
#include "render/settings.h"

namespace fh {

class PassRenderer {
 public:
  virtual ~PassRenderer() = default;

  // Passes are numbered locally (0, 1, ... on this device) and mapped to global passes,
  // which seed the samples. Whether a pass of these pixels (null: every pixel) fits now,
  // with `granted` granted and `returned` returned so far.
  virtual bool fits(const std::shared_ptr<const RoundPixels>& pixels, uint64_t granted, uint64_t returned) const = 0;
  virtual void grantPass(uint64_t local, uint32_t global, std::shared_ptr<const RoundPixels> pixels) = 0;
  // Lets the passes granted so far start; once per batch, after its grants.
  virtual void startGrantedPasses() = 0;
  virtual uint32_t globalPass(uint64_t local) const = 0;

  // Queues work; returns at once (the device runs it later).
  virtual void enqueueIteration() = 0;
  // Waits for the work queued and reads back which passes are complete.
  virtual void readCounters() = 0;
  virtual bool passComplete(uint64_t local) const = 0;
  // Reads a complete pass's samples (rgb, 1 for each pixel it covers, in the order of its
  // pixel list; then, with surface AOVs, kAovFloatsPerPixel for each) and frees its slot.
  virtual void takePass(uint64_t local, std::vector<float>& samples) = 0;

  // This device's counts so far (samples are the film's to count) and stage times.
  virtual RenderStats stats() = 0;
  virtual size_t wavefront() const = 0;
  virtual Strategy strategy() const = 0;
};

}  // namespace fh
