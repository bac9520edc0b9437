// Handing out passes, and merging them in order.
#include "render/pass_pool.h"

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <utility>

#include "base/error.h"
#include "base/test_hooks.h"
#include "render/adaptive.h"
#include "render/checkpoint.h"
#include "render/film_watcher.h"

namespace fh {
namespace {
double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// The passes a render may number: spp, or for an adaptive render, whose passes cover fewer
// pixels, as many as its sample budget takes, up to the last whole round that 32-bit pass
// numbers hold (a pass and the pixel seed a sample apart, kernels/sampler.h, so passes of
// any image may go that far).
uint32_t passLimit(const RenderSettings& s) {
  return s.adaptive ? uint32_t(0) - 2 * kAdaptiveLongestRound : uint32_t(std::max(1, s.spp));
}
}  // namespace

PassPool::PassPool(const RenderSettings& s, const RenderLinks& links, int workers)
    : settings_(s),
      links_(links),
      total_(passLimit(s)),
      film_(links.resume ? *links.resume : Film(s.width, s.height, s.surfaceAovs, s.replicates() == 2, s.firstPass)),
      stop_(s, links.resume.get()),
      rounds_(s, total_, film_),
      outstanding_(size_t(workers)),
      done_(size_t(workers), 0),
      progress_(s.progress),
      lastCheckpoint_(std::chrono::steady_clock::now()) {
  film_.radianceUnit = s.radianceUnit;
  film_.depthUnit = s.depthUnit;
  // A resumed render goes on from the first pass its film lacks; a chunk starts at its first.
  next_ = nextToMerge_ = firstNew_ = uint32_t(film_.nextPass());
  mergedSamples_ = resumedSamples_ = film_.samples();
  samplesDone_.assign(size_t(workers), 0);
  clocks_.resize(size_t(workers));
  killAfter_ = testHooks().killAfterPasses;
  merger_ = std::thread([this] { mergeInOrder(); });
}

PassPool::~PassPool() { stopMerging(); }

void PassPool::stopMerging() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (merger_.joinable()) merger_.join();
}

// The next pass for `worker`. With a time budget, no new pass starts once it is spent;
// those started finish, so every pixel ends with the same sample count. When none is left
// but other workers still have passes in flight, a worker with none of its own waits: if
// one of them fails, its passes come back here and must find a worker still running. (A
// worker with passes of its own never waits; it asks again after its next batch.)
bool PassPool::take(int worker, Pass& pass) {
  std::unique_lock<std::mutex> lock(mutex_);
  stop_.start();
  for (;;) {
    if (links_.stopRequested()) return false;
    if (!requeued_.empty()) {
      pass.index = requeued_.front();
      requeued_.pop_front();
      break;
    }
    if (stop_.noiseReached()) return false;
    const NewPass next = mergerBehind() ? NewPass::Later : nextNewPass(pass.index);
    if (next == NewPass::Given) break;
    const bool mine = !outstanding_[size_t(worker)].empty();
    if (mine || (next == NewPass::None && !anyOutstanding())) return false;
    changed_.wait(lock);
  }
  pass.pixels = rounds_.roundOf(pass.index)->pixels;
  outstanding_[size_t(worker)].insert(pass.index);
  return true;
}

// Finished passes wait in memory for the merger, which adds them one at a time: a fast GPU
// outruns it on large images, and the waiting passes grew by gigabytes. Past a budget, no
// new pass starts until the merger catches up (workers finish the passes they hold).
bool PassPool::mergerBehind() const {
  constexpr size_t kPendingBudgetBytes = size_t(512) << 20;
  size_t bytes = 0;
  for (const auto& entry : pending_) bytes += entry.second.size() * sizeof(float);
  return pending_.size() >= 2 && bytes >= kPendingBudgetBytes;
}

// A pass no one has rendered yet: from the ledger where processes share the render, else
// the next in this process's count, while the sample count (an adaptive render's sample
// budget) and the time budget allow; Later at the end of an adaptive round.
PassPool::NewPass PassPool::nextNewPass(uint32_t& pass) {
  if (links_.ledger) {
    if (ledgerDry_) return NewPass::None;
    if (links_.ledger->next(pass)) return NewPass::Given;
    ledgerDry_ = true;  // ask no more: for another process, each question is a message
    return NewPass::None;
  }
  // However short the time budget, a render renders its least passes (RenderSettings::minPasses).
  const bool fewest = next_ - firstNew_ < std::max(1u, settings_.minPasses);
  if (next_ >= total_ || (!fewest && stop_.outOfTime())) return NewPass::None;
  const PassRounds::Round* round = rounds_.roundOf(next_);
  if (!round) return NewPass::Later;
  if (!rounds_.takeFromBudget(*round)) return NewPass::None;
  pass = next_++;
  return NewPass::Given;
}

// Takes the samples over (the worker's vector is left empty) and returns at once.
void PassPool::done(int worker, uint32_t pass, std::vector<float>& samples) {
  std::lock_guard<std::mutex> lock(mutex_);
  outstanding_[size_t(worker)].erase(pass);
  ++done_[size_t(worker)];
  samplesDone_[size_t(worker)] += rounds_.roundOf(pass)->size;
  WorkerClock& clock = clocks_[size_t(worker)];
  clock.last = std::chrono::steady_clock::now();
  if (done_[size_t(worker)] == 1) {
    clock.first = clock.last;
    clock.samplesAtFirst = samplesDone_[size_t(worker)];
  }
  pending_[pass].swap(samples);
  changed_.notify_all();
}

void PassPool::reuse(std::vector<float>& samples) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!samples.empty() || spare_.empty()) return;
  samples.swap(spare_.back());
  spare_.pop_back();
}

void PassPool::fail(int worker) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (uint32_t pass : outstanding_[size_t(worker)]) requeued_.push_back(pass);
  outstanding_[size_t(worker)].clear();
  changed_.notify_all();
}

double PassPool::samplesPerSecondAfterFirstPass() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return steadyRate();
}

double PassPool::secondsToFirstPass() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return firstPassSeconds();
}

uint64_t PassPool::passesDone(int worker) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return done_[size_t(worker)];
}

uint64_t PassPool::samplesDone(int worker) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samplesDone_[size_t(worker)];
}

Film PassPool::finish(bool& complete) {
  stopMerging();
  std::lock_guard<std::mutex> lock(mutex_);
  checkpoint(true);
  complete = stop_.noiseReached() || (pending_.empty() && requeued_.empty() && !anyOutstanding());
  for (auto& [pass, samples] : pending_) {
    if (stop_.noiseReached()) break;  // beyond the pass that met the target
    const PassRounds::Round& round = *rounds_.roundOf(pass);
    film_.addPass(pass, samples, round.list());
    mergedSamples_ += double(round.size);
  }
  pending_.clear();
  spare_.clear();  // a frame of samples each
  if (links_.ledger) progress_.end();  // other processes may still be rendering
  else progress_.finish(uint64_t(mergedSamples_ - resumedSamples_), stop_.elapsed(), steadyRate(), firstPassSeconds());
  return std::move(film_);  // not a copy of its sums (64 bytes a pixel): the pool is done with it
}

bool PassPool::anyOutstanding() const {
  for (const auto& o : outstanding_)
    if (!o.empty()) return true;
  return false;
}

// The merger thread: passes join the film in pass order, so the image for a seed is the
// same bits whichever devices rendered which passes, and in whatever order they finished.
// With a ledger (processes sharing the render) this process holds some passes only, and
// they join as they come. A pass is added outside the lock: workers hand over passes meanwhile.
void PassPool::mergeInOrder() {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool anyOrder = links_.ledger != nullptr;
  for (;;) {
    changed_.wait(lock, [&] { return stopping_ || (anyOrder ? !pending_.empty() : pending_.count(nextToMerge_) > 0); });
    const auto next = anyOrder ? pending_.begin() : pending_.find(nextToMerge_);
    if (next == pending_.end()) return;  // stopping, and the next pass is not in
    std::vector<float> samples;
    samples.swap(next->second);
    const uint32_t pass = next->first;
    pending_.erase(next);
    const PassRounds::Round round = *rounds_.roundOf(pass);  // the merger alone adds and drops rounds
    lock.unlock();
    film_.addPass(pass, samples, round.list());
    if (links_.watcher && links_.watcher->wantsFrame()) links_.watcher->show(film_);
    const bool check = stop_.checksNoise(film_);
    const double estimate = check ? film_.estimatedRelMse() : -1.0;
    if (links_.ledger) links_.ledger->finished(pass);
    // At an adaptive round's choice point, the round after it is chosen.
    auto following = rounds_.choosesAfter(pass, round) ? rounds_.pixelsOfRoundAfter(round.begin) : nullptr;
    lock.lock();
    // One spare a worker at most: passes that piled up for the merger (up to its budget,
    // mergerBehind) leave no frames behind them.
    if (spare_.size() < done_.size()) spare_.push_back(std::move(samples));
    ++nextToMerge_;
    mergedSamples_ += double(round.size);
    // Workers may wait for a new round, or for the merger to catch up.
    rounds_.merged(pass, round, std::move(following), nextToMerge_);
    changed_.notify_all();
    checkpoint(false);
    const bool met = check && stop_.meets(estimate);
    showProgress();
    if (met) {  // no more passes start, and none after this one is merged
      changed_.notify_all();
      return;
    }
  }
}

// Saves the film, every settings_.checkpointSeconds and at the end (final). A checkpoint
// that cannot be written is a warning: the render is worth more than its checkpoint.
void PassPool::checkpoint(bool final) {
  if (settings_.checkpointPath.empty()) return;
  if (!final && secondsSince(lastCheckpoint_) < settings_.checkpointSeconds) return;
  try {
    saveCheckpoint(settings_.checkpointPath, film_, settings_.fingerprint);
  } catch (const std::exception& e) {
    if (warnings_.empty()) warnings_.push_back(std::string("no checkpoint written: ") + e.what());
  }
  lastCheckpoint_ = std::chrono::steady_clock::now();
  if (killAfter_ >= 0 && film_.passes() >= uint64_t(killAfter_)) raise(SIGKILL);  // a crash, for the tests
}

std::vector<std::string> PassPool::warnings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return warnings_;
}

// Samples a second: each device's from the end of its first pass to the end of its latest,
// summed over the devices; 0 until one has finished two passes.
double PassPool::steadyRate() const {
  double rate = 0.0;
  for (size_t w = 0; w < clocks_.size(); ++w) {
    const double seconds = std::chrono::duration<double>(clocks_[w].last - clocks_[w].first).count();
    if (done_[w] >= 2 && seconds > 0.0) rate += double(samplesDone_[w] - clocks_[w].samplesAtFirst) / seconds;
  }
  return rate;
}

// From the first pass handed out to the first finished (with the kernels' build); 0: none yet.
double PassPool::firstPassSeconds() const {
  double first = 0.0;
  for (size_t w = 0; w < clocks_.size(); ++w) {
    if (done_[w] == 0) continue;
    const double seconds = std::chrono::duration<double>(clocks_[w].first - stop_.startTime()).count();
    first = first > 0.0 ? std::min(first, seconds) : seconds;
  }
  return first;
}

void PassPool::showProgress() {
  // This run's work only: a chunk's passes, or those a resumed render adds to its checkpoint.
  const uint64_t passes = total_ - std::min(total_, firstNew_);
  const uint64_t elsewhere = links_.ledger ? links_.ledger->finishedElsewhere() : 0;
  const uint64_t samples =
      settings_.adaptive ? rounds_.sampleBudget() - uint64_t(resumedSamples_) : passes * film_.pixels();
  // With a budget of time or noise, the share done is the budget's, not the samples'.
  const bool budgeted = stop_.timed() || stop_.noisy();
  progress_.update(uint64_t(mergedSamples_ - resumedSamples_) + elsewhere * film_.pixels(), budgeted ? 0 : samples,
                   stop_.elapsed(), stop_.share(), steadyRate());
}

}  // namespace fh
