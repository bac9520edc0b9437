// The passes of one render in one process: handed out to device workers until the sample
// count, the time budget or the noise target is reached, merged into the film in pass order
// by a thread of its own (a worker hands a pass over and goes back to feeding its device),
// with one progress display. One device is a pool with one worker.
//
// A noise target is checked on the film after each merged pass, so the render ends with the
// first pass count whose film meets it: passes finished beyond it are dropped, and the image
// for a seed and target is the same whichever devices rendered and however fast.
//
// The pool schedules; two parts decide with it. StopRules (render/stop_rules.h): the time
// budget and the noise target. PassRounds (render/pass_rounds.h): which pixels each pass
// covers. An adaptive render's passes come in rounds (render/adaptive.h): the merger chooses
// a round's pixels once the film holds every pass before the round before it, and workers
// wait for them only if they get that far ahead. Its sample count is a budget: spp times
// the pixels, over whichever pixels the rounds cover.
#pragma once
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "render/film.h"
#include "render/pass_ledger.h"
#include "render/pass_rounds.h"
#include "render/pass_source.h"
#include "render/progress.h"
#include "render/settings.h"
#include "render/stop_rules.h"

namespace fh {

class PassPool : public PassSource {
 public:
  PassPool(const RenderSettings& s, const RenderLinks& links, int workers);
  ~PassPool() override;

  bool take(int worker, Pass& pass) override;
  void done(int worker, uint32_t pass, std::vector<float>& samples) override;
  void reuse(std::vector<float>& samples) override;
  void fail(int worker) override;

  uint64_t passesDone(int worker) const;
  // Samples a second after each worker's first pass, summed (0: none finished two); and the
  // seconds from the first pass handed out to the first finished.
  double samplesPerSecondAfterFirstPass() const;
  double secondsToFirstPass() const;
  uint64_t samplesDone(int worker) const;
  // Ends the render: saves the checkpoint (the passes merged in order), merges whatever
  // finished out of order (passes lost with every device leave gaps: the film records which
  // passes it holds), closes the progress display, and hands the film over (once). `complete` is
  // false when some pass was never rendered.
  Film finish(bool& complete);
  // Checkpoints that could not be written (the render goes on without them).
  std::vector<std::string> warnings() const;

 private:
  bool anyOutstanding() const;
  enum class NewPass { Given, Later, None };  // Later: once the merger chooses the next round
  NewPass nextNewPass(uint32_t& pass);
  bool mergerBehind() const;  // under the lock
  double steadyRate() const;        // under the lock
  double firstPassSeconds() const;  // under the lock
  void mergeInOrder();
  void stopMerging();
  void showProgress();
  void checkpoint(bool final);

  mutable std::mutex mutex_;
  std::condition_variable changed_;  // passes finished, or came back from a failed worker
  const RenderSettings settings_;
  const RenderLinks links_;
  const uint32_t total_;
  // Every member below is guarded by mutex_; the film and the rounds' choices are the
  // merger's, which works on them outside the lock.
  Film film_;
  StopRules stop_;     // time budget, noise target
  PassRounds rounds_;  // which pixels each pass covers
  uint32_t next_ = 0, nextToMerge_ = 0;
  uint32_t firstNew_ = 0;  // the first pass this render hands out (a time budget allows it always)
  double mergedSamples_ = 0;  // in the film
  double resumedSamples_ = 0;  // in the film a resumed render started from: not this run's work
  std::vector<uint64_t> samplesDone_;
  // Per worker: when its first and latest passes finished, and its samples at the first. The
  // first pass carries the kernels' build (PoCL compiles at the first launch): rates count
  // from its end.
  struct WorkerClock {
    std::chrono::steady_clock::time_point first, last;
    uint64_t samplesAtFirst = 0;
  };
  std::vector<WorkerClock> clocks_;
  std::deque<uint32_t> requeued_;
  std::vector<std::set<uint32_t>> outstanding_;
  std::vector<uint64_t> done_;
  std::map<uint32_t, std::vector<float>> pending_;  // finished, not yet merged
  std::vector<std::vector<float>> spare_;           // merged passes' buffers, for reuse
  Progress progress_;
  bool stopping_ = false;
  std::chrono::steady_clock::time_point lastCheckpoint_;
  std::vector<std::string> warnings_;
  long killAfter_ = -1;  // FREDHOLM_KILL_AFTER_PASSES (tests): SIGKILL once that many are saved
  bool ledgerDry_ = false;  // the ledger said no more
  std::thread merger_;
};

}  // namespace fh
