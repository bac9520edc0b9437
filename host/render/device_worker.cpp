// The device worker's loop.
#include "render/device_worker.h"

#include <string>

#include "base/error.h"
#include "render/wavefront.h"

namespace fh {

void DeviceWorker::run(const RenderLinks& links) {
  takePasses();
  while ((returned_ < granted_ || held_) && !links.stopRequested()) {
    for (int i = 0; i < kIterationsPerBatch; ++i) pipeline_.enqueueIteration();
    pipeline_.readCounters();
    returnCompletePasses();
    takePasses();
  }
}

// New passes while they fit in the pipeline. One that does not fit yet (its samples would
// overrun the pass buffers, or its shape waits for the older shape's samples to start) is
// held for the next batch.
void DeviceWorker::takePasses() {
  const uint64_t before = granted_;
  for (;;) {
    if (!held_) {
      if (granted_ - returned_ >= FH_MAX_PASS_SLOTS || !source_.take(index_, heldPass_)) break;
      held_ = true;
    }
    if (!pipeline_.fits(heldPass_.pixels, granted_, returned_)) break;
    pipeline_.grantPass(granted_++, heldPass_.index, std::move(heldPass_.pixels));
    held_ = false;
  }
  if (granted_ != before) pipeline_.startGrantedPasses();
}

// Every complete pass, in local order (a pass's slot is reused only after it is returned).
void DeviceWorker::returnCompletePasses() {
  while (returned_ < granted_ && pipeline_.passComplete(returned_)) {
    const uint32_t pass = pipeline_.globalPass(returned_);
    source_.reuse(samples_);
    pipeline_.takePass(returned_, samples_);
    if (failAfter_ >= 0 && long(returned_) >= failAfter_)
      throw Error("simulated failure (FREDHOLM_FAIL_DEVICE) on finishing pass " + std::to_string(pass));
    ++returned_;
    source_.done(index_, pass, samples_);
  }
}

}  // namespace fh
