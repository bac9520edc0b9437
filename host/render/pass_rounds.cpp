// Rounds of passes: which pixels each pass covers, and where each pixel is in its sequence.
#include "render/pass_rounds.h"

#include <algorithm>
#include <string>
#include <utility>

#include "base/error.h"
#include "render/adaptive.h"

namespace fh {

PassRounds::PassRounds(const RenderSettings& s, uint32_t total, Film& film)
    : adaptive_(s.adaptive), total_(total), film_(film) {
  if (!adaptive_) {
    add(0, nullptr);
    return;
  }
  sampleBudget_ = uint64_t(std::max(1, s.spp)) * film_.pixels();
  samplesHanded_ = uint64_t(film_.samples());
  // The round the film goes on with and, past its choice point, the one after it, both
  // chosen before the film got here (the first covers every pixel): a film saved in a
  // later round lists them.
  const uint32_t next = uint32_t(film_.nextPass());
  const uint32_t begin = adaptiveRoundBegin(next), end = adaptiveRoundEnd(begin);
  const auto missing = [&](const char* which) {
    return Error("--resume: the film ends in an adaptive round (at pass " + std::to_string(next) +
                 ") and does not say which pixels " + which + " covers");
  };
  if (begin > 0 && !film_.roundPixels) throw missing("it");
  add(begin, begin > 0 ? film_.roundPixels : nullptr);
  if (next < adaptiveChoicePoint(begin)) {  // the merger chooses it
  } else if (film_.nextRoundPixels) add(end, film_.nextRoundPixels);
  else if (next == adaptiveChoicePoint(begin)) add(end, pixelsOfRoundAfter(begin));
  else throw missing("the round after it");
  record(next);
}

const PassRounds::Round* PassRounds::roundOf(uint32_t pass) const {
  for (const Round& r : rounds_)
    if (pass >= r.begin && pass < r.end) return &r;
  return nullptr;
}

bool PassRounds::takeFromBudget(const Round& round) {
  if (!adaptive_) return true;
  if (samplesHanded_ + round.size > sampleBudget_) return false;
  samplesHanded_ += round.size;
  return true;
}

bool PassRounds::choosesAfter(uint32_t pass, const Round& round) const {
  return adaptive_ && pass + 1 == adaptiveChoicePoint(round.begin);
}

std::shared_ptr<const PixelList> PassRounds::pixelsOfRoundAfter(uint32_t begin) const {
  const Round& round = *roundOf(begin);
  return adaptivePixels(film_, round.end, round.list(), round.end - adaptiveChoicePoint(begin));
}

bool PassRounds::merged(uint32_t pass, const Round& round, std::shared_ptr<const PixelList> following,
                        uint32_t nextToMerge) {
  const bool chooses = choosesAfter(pass, round);
  const bool ends = adaptive_ && pass + 1 == round.end;
  if (ends) rounds_.pop_front();
  if (chooses) add(round.end, std::move(following));
  if (chooses || ends) record(nextToMerge);
  return chooses || ends;
}

// The round from pass `begin` on covers `pixels` (null, or every pixel listed: every pixel).
void PassRounds::add(uint32_t begin, std::shared_ptr<const PixelList> pixels) {
  if (pixels && pixels->size() == film_.pixels()) pixels = nullptr;
  const size_t size = pixels ? pixels->size() : film_.pixels();
  std::shared_ptr<const RoundPixels> round;
  if (adaptive_) {
    std::vector<uint32_t> offsets = sequenceOffsets(begin, pixels.get());
    if (pixels || std::any_of(offsets.begin(), offsets.end(), [](uint32_t o) { return o != 0; }))
      round = std::make_shared<const RoundPixels>(
          RoundPixels{pixels ? *pixels : everyPixel(film_.pixels()), std::move(offsets)});
  }
  rounds_.push_back({begin, adaptive_ ? adaptiveRoundEnd(begin) : total_, std::move(round), size});
}

// Where each pixel listed (null: every pixel) is in its sequence when the round from pass
// `begin` on starts: its sample count then, less `begin`. The film holds the passes before
// its nextPass(); the rounds known between it and `begin` add theirs, and a round the film
// is already into (a resumed render's) takes its own off. The counts are whole rounds'
// lengths, which are even, so a point's parity is its pass's (kernels/sampler.h).
std::vector<uint32_t> PassRounds::sequenceOffsets(uint32_t begin, const PixelList* pixels) const {
  std::vector<double> counts(film_.pixels());
  for (size_t p = 0; p < counts.size(); ++p) counts[p] = film_.count(p);
  const auto add = [&](const PixelList* list, double passes) {
    if (!list)
      for (double& c : counts) c += passes;
    else
      for (uint32_t p : *list) counts[p] += passes;
  };
  const uint32_t held = uint32_t(film_.nextPass());
  if (held > begin) add(pixels, -double(held - begin));
  for (const Round& r : rounds_) {
    const uint32_t from = std::max(r.begin, held), to = std::min(r.end, begin);
    if (from < to) add(r.list(), double(to - from));
  }
  std::vector<uint32_t> offsets;
  const auto offset = [&](uint32_t p) { offsets.push_back(uint32_t(counts[p]) - begin); };
  if (!pixels)
    for (uint32_t p = 0; p < counts.size(); ++p) offset(p);
  else
    for (uint32_t p : *pixels) offset(p);
  return offsets;
}

// What a checkpoint of the film needs to go on: the pixels of the round its next pass is
// in and, once chosen, of the round after it (every pixel listed, where they cover every
// pixel); none in the first round.
void PassRounds::record(uint32_t nextToMerge) {
  const auto listed = [&](const Round* r) -> std::shared_ptr<const PixelList> {
    if (!r || r->begin < kAdaptiveFirstRound) return nullptr;
    if (r->pixels) return std::shared_ptr<const PixelList>(r->pixels, &r->pixels->pixels);
    if (!everyPixel_) everyPixel_ = std::make_shared<const PixelList>(everyPixel(film_.pixels()));
    return everyPixel_;
  };
  const Round* current = roundOf(nextToMerge);
  film_.roundPixels = listed(current);
  film_.nextRoundPixels = film_.roundPixels ? listed(roundOf(current->end)) : nullptr;
}

}  // namespace fh
