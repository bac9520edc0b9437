// Where a render's passes come from and where finished ones go. A pass is one sample for
// each pixel it covers: every pixel, or in an adaptive render the pixels of its round
// (render/adaptive.h); global pass k seeds its samples, so a pass is the same image
// whichever device renders it. Device workers take passes, render them and hand them
// back; the source merges them into one film in pass order. Called from the workers' threads.
#pragma once
#include <cstdint>
#include <memory>
#include <numeric>
#include <vector>

namespace fh {

// The pixels a pass covers, ascending pixel indices; shared by the passes of a round.
using PixelList = std::vector<uint32_t>;

// The list of every one of `pixels` pixels.
inline PixelList everyPixel(size_t pixels) {
  PixelList list(pixels);
  std::iota(list.begin(), list.end(), 0u);
  return list;
}

// The pixels a round's passes cover (render/adaptive.h) and where each one's samples are in
// its own sequence: pass k's sample of listed pixel i is point k + offsets[i] (mod 2^32) of
// that pixel's sequence. An adaptive render sets the offsets so that every pixel's samples
// are the first points of its sequence, however many rounds passed it by: the first 2^m
// points of a low-discrepancy sequence are a net, points from scattered blocks of it are not.
struct RoundPixels {
  PixelList pixels;
  std::vector<uint32_t> offsets;  // one per listed pixel
};

struct Pass {
  uint32_t index = 0;
  std::shared_ptr<const RoundPixels> pixels;  // null: every pixel, its sample k point k
};

class PassSource {
 public:
  virtual ~PassSource() = default;
  // The next pass for `worker`; false when the render needs no more from it. A pass may
  // cover other pixels than the worker's last (the next adaptive round's) while earlier
  // passes are still in flight: a device may have passes of two shapes in flight, and its
  // worker holds a pass of a third until every sample of the oldest has started
  // (WavefrontPipeline::fits, render/wavefront.h).
  virtual bool take(int worker, Pass& pass) = 0;
  // A finished pass's samples: rgb and 1 for each pixel it covers, in order (may be
  // swapped out: `samples` is then left empty).
  virtual void done(int worker, uint32_t pass, std::vector<float>& samples) = 0;
  // Swaps the buffer of a pass merged already into an empty `samples`, to take the next pass
  // (asked for then, not when a pass is done: a buffer is a frame of samples, and the
  // one merged meanwhile serves); may leave it empty.
  virtual void reuse(std::vector<float>& samples) { (void)samples; }
  // The worker stopped: the passes it had taken must be rendered by others.
  virtual void fail(int worker) = 0;
};

}  // namespace fh
