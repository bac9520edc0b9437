// The device worker's loop.
#include "render/device_worker.h"

#include <string>

#include "base/error.h"

namespace fh {

// Iterations queued between reads of the device's books: enough that the device is never
// idle waiting for the host, few enough that finished passes leave soon.
constexpr int kIterationsPerBatch = 8;

void DeviceWorker::run(const RenderSettings& settings) {
  takePasses();
  while (returned_ < granted_ && !settings.stopRequested()) {
    for (int i = 0; i < kIterationsPerBatch; ++i) pipeline_.enqueueIteration();
    pipeline_.readCounters();
    returnCompletePasses();
    takePasses();
  }
}

// New passes while fewer than passSlots() are unfinished. A pass of another shape (an
// adaptive round's pixels) comes only when none is in flight: the pipeline switches to it.
void DeviceWorker::takePasses() {
  const uint64_t before = granted_;
  Pass pass;
  while (granted_ - returned_ < pipeline_.passSlots() && source_.take(index_, pass)) {
    if (pass.pixels != pipeline_.passPixels()) {
      if (granted_ != returned_) throw Error("internal: a pass of another shape while passes are in flight");
      pipeline_.setPassPixels(pass.pixels, granted_);
    }
    pipeline_.grantPass(granted_++, pass.index);
  }
  if (granted_ != before) pipeline_.startGrantedPasses(granted_);
}

// Every complete pass, in local order (a pass's slot is reused only after it is returned).
void DeviceWorker::returnCompletePasses() {
  while (returned_ < granted_ && pipeline_.passComplete(returned_)) {
    const uint32_t pass = pipeline_.globalPass(returned_);
    pipeline_.takePass(returned_, samples_);
    if (failAfter_ >= 0 && long(returned_) >= failAfter_)
      throw Error("simulated failure (FREDHOLM_FAIL_DEVICE) on finishing pass " + std::to_string(pass));
    ++returned_;
    source_.done(index_, pass, samples_);
  }
}

}  // namespace fh
