// Adaptive sampling (--adaptive): after a first round of passes over every pixel, each
// round's passes cover only the pixels where more samples lower the image's error most.
//
// A pixel's value stays the mean of its own samples, each one unbiased; only how many it
// gets depends on the samples so far (its block's noise), which makes the image consistent
// rather than strictly unbiased, as in every renderer that samples adaptively. Every pixel
// keeps getting samples (at least one for every kAdaptiveMaxSpread of the busiest pixel's),
// so every pixel converges.
//
// Rounds are fixed runs of passes: [0, 16) over every pixel, then runs of 16 passes up to
// pass 64, then runs half as long as the passes before them (64:96, 96:128, 128:192,
// 192:256), then of 64 (a pixel a round takes in gets no more than 64 samples at once).
// Each is a power of two long and starts at a multiple of its length. A pixel's samples are
// the first points of its low-discrepancy sequence, as many as it got (the round's sequence
// offsets, render/pass_source.h), so its counts at the ends of rounds are nets where it
// matters most: not the points of the passes that covered it, which are scattered blocks of
// the sequence (whose union is stratified no better than its blocks).
//
// A round's pixels are chosen from the film once it holds the first half of the round
// before it, counting the samples the rest of that round adds (the second round's, once it
// holds the whole first round: less would be too little to go by). So a round is known
// before the one before it ends: devices go from round to round without running dry, and
// passes of two rounds may be in flight at once; and a pixel whose noise shows (a caustic
// path found) is taken in at most one and a half rounds later. The film is merged in pass
// order, so a seed gives the same rounds and the same image whichever devices render them.
#pragma once
#include <cstdint>
#include <memory>

#include "render/film.h"
#include "render/pass_source.h"

namespace fh {

// Passes over every pixel before any round adapts (also where a noise target starts checking).
constexpr uint32_t kAdaptiveFirstRound = 16;
// The longest round, in passes.
constexpr uint32_t kAdaptiveLongestRound = 64;
// No pixel's sample count falls behind the busiest's by more than this factor.
constexpr uint32_t kAdaptiveMaxSpread = 16;
// A round covers at least this share of the pixels, so its passes still fill a wavefront.
constexpr uint32_t kAdaptiveMinShare = 8;  // one pixel in 8

// A round covers some pixels only where a sample there takes this many times more error off
// than a sample of every pixel's would, on average (else it covers every pixel): a round of
// some pixels costs more per sample (their paths are longer, its passes smaller), and on
// scenes noisy everywhere, such as the Cornell box, smaller gains did not pay (bench/RESULTS.md).
constexpr double kAdaptiveLeastGain = 1.5;

// The end of the round that starts at pass `begin` (a round boundary).
uint32_t adaptiveRoundEnd(uint32_t begin);
// The round boundary at or before pass `pass`.
uint32_t adaptiveRoundBegin(uint32_t pass);
// The passes the film holds when it chooses the pixels of the round after the one that
// starts at pass `begin`: up to halfway through that round; the first round's, all of it.
uint32_t adaptiveChoicePoint(uint32_t begin);

// The pixels the round starting at pass `begin` covers (null: every pixel), chosen from
// `film`, which holds the passes up to the round before it's choice point; the rest of that
// round, `beforeLength` passes, covers `before` (null: every pixel), and is counted as if in.
// Null where the film holds fewer than kAdaptiveFirstRound passes. Else the pixels whose
// error falls fastest per sample (relative variance over count, averaged over a 3x3 block,
// then the largest over 3x3, so a pixel whose samples missed a light its neighbours found
// is not dropped), down to a quarter of the busiest's: those that, after their samples
// double, still lose error as fast as the busiest do now. Null again where they would gain
// less than kAdaptiveLeastGain over a round of every pixel. Ascending pixel indices.
std::shared_ptr<const PixelList> adaptivePixels(const Film& film, uint32_t begin, const PixelList* before,
                                                uint32_t beforeLength);

}  // namespace fh
