// The rounds of a render: runs of passes over the same pixels. A render's passes are one
// round over every pixel; an adaptive render's (render/adaptive.h) are rounds whose pixels
// are chosen from the film as it converges, each before the workers reach it. Not
// thread-safe: the pass pool calls it under its lock, and only its merger adds rounds.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "render/film.h"
#include "render/pass_source.h"
#include "render/settings.h"

namespace fh {

class PassRounds {
 public:
  struct Round {
    uint32_t begin = 0, end = 0;
    std::shared_ptr<const RoundPixels> pixels;  // null: every pixel, from its pass's point on
    size_t size = 0;                            // pixels covered
    const PixelList* list() const { return pixels ? &pixels->pixels : nullptr; }  // null: every pixel
  };

  // The rounds from the film's next pass on (a resumed render's film says which pixels its
  // rounds cover); `film` is read to choose pixels and written with what a checkpoint needs.
  PassRounds(const RenderSettings& s, uint32_t total, Film& film);

  // The round pass `pass` is in; null: its pixels are not chosen yet.
  const Round* roundOf(uint32_t pass) const;
  // Whether an adaptive render's sample budget has room for another pass of `round`, which
  // it then counts as handed out.
  bool takeFromBudget(const Round& round);
  uint64_t sampleBudget() const { return sampleBudget_; }

  // Whether merging `pass` (of `round`) reaches the choice point of the round after it.
  bool choosesAfter(uint32_t pass, const Round& round) const;
  // The pixels of the round after the one from pass `begin` on, chosen from the film, which
  // holds every pass before that round's choice point.
  std::shared_ptr<const PixelList> pixelsOfRoundAfter(uint32_t begin) const;
  // After `pass` of `round` is merged: drops a round that ended, adds the one chosen
  // (`following`, when choosesAfter), and records them for checkpoints. Returns whether the
  // rounds changed (workers may be waiting for one).
  bool merged(uint32_t pass, const Round& round, std::shared_ptr<const PixelList> following, uint32_t nextToMerge);

 private:
  void add(uint32_t begin, std::shared_ptr<const PixelList> pixels);
  std::vector<uint32_t> sequenceOffsets(uint32_t begin, const PixelList* pixels) const;
  void record(uint32_t nextToMerge);

  const bool adaptive_;
  const uint32_t total_;
  Film& film_;
  std::deque<Round> rounds_;  // the rounds whose pixels are known, in order, from the one being merged on
  std::shared_ptr<const PixelList> everyPixel_;  // a checkpoint's list for rounds of every pixel
  uint64_t sampleBudget_ = 0, samplesHanded_ = 0;  // an adaptive render's
};

}  // namespace fh
