// Where a render's passes come from and where finished ones go. A pass is one sample per
// pixel; global pass k seeds its samples, so a pass is the same image whichever device
// renders it. Device workers take passes, render them and hand them back; the source
// merges them into one film in pass order. Called from the workers' threads.
#pragma once
#include <cstdint>
#include <vector>

namespace fh {

class PassSource {
 public:
  virtual ~PassSource() = default;
  // The next pass for `worker`; false when the render needs no more from it.
  virtual bool take(int worker, uint32_t& pass) = 0;
  // A finished pass's samples: rgb and 1 per pixel, pixel-major (may be swapped out).
  virtual void done(int worker, uint32_t pass, std::vector<float>& samples) = 0;
  // The worker stopped: the passes it had taken must be rendered by others.
  virtual void fail(int worker) = 0;
};

}  // namespace fh
