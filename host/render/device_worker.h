// One device's part in a render: it takes passes from the source while they fit in its
// pipeline, queues iterations in batches, and hands each pass back as soon as it is complete.
#pragma once
#include "render/pass_source.h"
#include "render/pass_renderer.h"

namespace fh {

class DeviceWorker {
 public:
  // `failAfter` >= 0 simulates the device failing when it finishes that many passes
  // (FREDHOLM_FAIL_DEVICE, for tests); -1: never.
  DeviceWorker(int index, PassRenderer& pipeline, PassSource& source, long failAfter = -1)
      : index_(index), pipeline_(pipeline), source_(source), failAfter_(failAfter) {}

  // Renders until the source has nothing more for this device, or `stop` is set (passes in
  // flight are then dropped). Throws if the device fails; the caller then tells the source
  // (fail), which gives its passes to the others.
  void run(const RenderLinks& links);
  uint64_t passesDone() const { return returned_; }

 private:
  void takePasses();
  void returnCompletePasses();

  int index_;
  PassRenderer& pipeline_;
  PassSource& source_;
  long failAfter_;
  uint64_t granted_ = 0, returned_ = 0;  // local passes
  Pass heldPass_;       // taken from the source, not yet granted: it did not fit
  bool held_ = false;
  std::vector<float> samples_;
};

}  // namespace fh
