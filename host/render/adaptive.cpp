// Choosing an adaptive round's pixels.
#include "render/adaptive.h"

#include <algorithm>
#include <vector>

#include "image/error_metrics.h"
#include "image/neighbourhood.h"

namespace fh {
namespace {

// Per pixel, how fast its error falls per sample once it has counts[p] samples: the
// relative variance of its mean (as relMSE weighs it, image/error_metrics.h), at that
// count, over the count. A pixel's variance is sigma^2 / n, so this is sigma^2 / n^2: what
// the next sample takes off.
std::vector<double> errorFallPerSample(const Film& film, const std::vector<double>& counts) {
  std::vector<double> fall(film.pixels(), 0.0);
  for (size_t p = 0; p < film.pixels(); ++p) {
    const double n = film.count(p);
    if (n <= 0) continue;
    const std::array<double, 3> variance = film.varianceOfMean(p);
    double relative = 0.0;
    for (size_t c = 0; c < 3; ++c) {
      const double mean = film.sum[4 * p + c] / n;
      relative += variance[c] / (mean * mean + kRelMseEpsilon);
    }
    fall[p] = relative * n / (3.0 * counts[p] * counts[p]);
  }
  return fall;
}

// The mean over each pixel's 3x3 block (a pixel's own estimate, from a few dozen samples,
// is a noisy ranking: the noisiest-looking are partly the luckiest draws; and one firefly is
// shared out, not followed), then the largest such mean over its 3x3 neighbourhood: a pixel
// beside a noisy block is sampled with it. (5x5 blocks ranked worse where the noise is
// fine-grained, as on the Veach plates: bench/RESULTS.md.)
std::vector<double> smoothed(const std::vector<double>& v, int width, int height) {
  return neighbourhoodMax(neighbourhoodMean(v, width, height, 1), width, height, 1);
}

// The value `share` of the way up the sorted values (0.999: all but the top thousandth).
double quantile(std::vector<double> values, double share) {
  const size_t k = std::min(values.size() - 1, size_t(share * double(values.size())));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

}  // namespace

uint32_t adaptiveRoundEnd(uint32_t begin) {
  if (begin < kAdaptiveFirstRound) return kAdaptiveFirstRound;
  uint32_t power = 1;  // the largest power of two <= begin
  while (power <= begin / 2) power *= 2;
  return begin + std::min(kAdaptiveLongestRound, std::max(kAdaptiveFirstRound, power / 2));
}

uint32_t adaptiveRoundBegin(uint32_t pass) {
  uint32_t begin = 0;
  while (adaptiveRoundEnd(begin) <= pass) begin = adaptiveRoundEnd(begin);
  return begin;
}

uint32_t adaptiveChoicePoint(uint32_t begin) {
  return begin < kAdaptiveFirstRound ? kAdaptiveFirstRound : begin + (adaptiveRoundEnd(begin) - begin) / 2;
}

std::shared_ptr<const PixelList> adaptivePixels(const Film& film, uint32_t begin, const PixelList* before,
                                                uint32_t beforeLength) {
  if (film.passes() < kAdaptiveFirstRound || film.pixels() == 0) return nullptr;
  std::vector<double> counts(film.pixels());
  for (size_t p = 0; p < film.pixels(); ++p) counts[p] = film.count(p) + (before ? 0.0 : beforeLength);
  if (before)
    for (uint32_t p : *before) counts[p] += beforeLength;
  const std::vector<double> fall = smoothed(errorFallPerSample(film, counts), film.width, film.height);
  // Doubling a pixel's samples quarters what a sample takes off: pixels within a quarter of
  // the busiest still gain as much after this round as the busiest does now. The busiest
  // are the top thousandth's edge, not the one pixel an outlier may have put on top.
  const double threshold = quantile(fall, 0.999) / 4.0;
  const double most = *std::max_element(counts.begin(), counts.end());
  std::vector<char> chosen(film.pixels(), 0);
  for (size_t p = 0; p < film.pixels(); ++p)
    chosen[p] = (fall[p] > 0.0 && fall[p] >= threshold) || counts[p] * kAdaptiveMaxSpread < most;
  const auto taken = [&] { return size_t(std::count(chosen.begin(), chosen.end(), char(1))); };
  // Too few for a full wavefront: the next most deserving too (ties by pixel index), of
  // those with any noise (a round of fewer fills the device less, but spends nothing on
  // pixels with nothing to gain).
  const size_t least = (film.pixels() + kAdaptiveMinShare - 1) / kAdaptiveMinShare;
  if (taken() < least) {
    std::vector<uint32_t> noisy;
    for (size_t p = 0; p < film.pixels(); ++p)
      if (fall[p] > 0.0) noisy.push_back(uint32_t(p));
    const size_t more = std::min(least, noisy.size());
    std::nth_element(noisy.begin(), noisy.begin() + std::ptrdiff_t(more), noisy.end(),
                     [&](uint32_t a, uint32_t b) { return fall[a] != fall[b] ? fall[a] > fall[b] : a < b; });
    for (size_t i = 0; i < more; ++i) chosen[noisy[i]] = 1;
  }
  const size_t count = taken();
  if (count == 0) return nullptr;
  // What a sample takes off, on average over the round, were its samples those pixels' or
  // every pixel's: the round is every pixel's unless choosing gains clearly more. Below
  // kAdaptiveLeastGain it does not pay: the noisiest pixels' samples are dearer (longer
  // paths), smaller passes fill the device less, and the ranking is itself an estimate.
  const double length = double(adaptiveRoundEnd(begin) - begin);
  double gainChosen = 0.0, gainAll = 0.0;
  for (size_t p = 0; p < film.pixels(); ++p) {
    const double gain = fall[p] * counts[p] / (counts[p] + length);
    gainAll += gain;
    if (chosen[p]) gainChosen += gain;
  }
  if (gainChosen / double(count) < kAdaptiveLeastGain * gainAll / double(film.pixels())) return nullptr;
  auto pixels = std::make_shared<PixelList>();
  for (size_t p = 0; p < film.pixels(); ++p)
    if (chosen[p]) pixels->push_back(uint32_t(p));
  return pixels;
}

}  // namespace fh
