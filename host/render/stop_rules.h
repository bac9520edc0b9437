// When a render stops handing out new passes, besides its pass count: its time budget spent
// (counted from the first pass handed out; passes started still finish, so every pixel ends
// with the same sample count), or its noise target met by the film (checked after each
// merged pass from kNoiseMinPasses on). Not thread-safe: the pass pool calls it under its lock.
#pragma once
#include <algorithm>
#include <chrono>

#include "render/film.h"
#include "render/settings.h"

namespace fh {

class StopRules {
 public:
  using Clock = std::chrono::steady_clock;

  // `resumed`: a film a render goes on from, which may have met the target already (a
  // render that stopped there).
  StopRules(const RenderSettings& s, const Film* resumed) : seconds_(s.seconds), noise_(s.noise) {
    noiseReached_ = resumed && noisy() && resumed->passes() >= kNoiseMinPasses && resumed->estimatedRelMse() <= noise_;
  }

  // The budget counts from the first pass handed out.
  void start() {
    if (started_) return;
    start_ = Clock::now();
    started_ = true;
  }
  Clock::time_point startTime() const { return start_; }
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  bool timed() const { return seconds_ > 0.0; }
  bool noisy() const { return noise_ > 0.0; }
  bool outOfTime() const { return timed() && elapsed() >= seconds_; }

  // Whether the film, after a merged pass, is held to the noise target.
  bool checksNoise(const Film& film) const { return noisy() && film.passes() >= kNoiseMinPasses; }
  // Records the film's estimated relMSE after a merged pass; true when it meets the target:
  // no more passes start, and none after that one is merged.
  bool meets(double estimate) {
    estimate_ = estimate;
    if (estimate <= noise_) noiseReached_ = true;
    return noiseReached_;
  }
  bool noiseReached() const { return noiseReached_; }

  // The share of the render done as the budgets see it, for the progress display: relMSE
  // falls as 1 / samples, so target / estimate is the share of samples taken; with both
  // budgets, the larger share. 0 without either.
  double share() const {
    const double byTime = timed() ? std::min(1.0, elapsed() / seconds_) : 0.0;
    if (!noisy()) return byTime;
    const double byNoise = estimate_ > 0.0 ? std::min(1.0, noise_ / estimate_) : 0.0;
    return std::min(1.0, std::max(byNoise, byTime));
  }

 private:
  const double seconds_, noise_;
  Clock::time_point start_ = Clock::now();
  bool started_ = false;
  bool noiseReached_ = false;
  double estimate_ = -1.0;  // the film's at the last check
};

}  // namespace fh
