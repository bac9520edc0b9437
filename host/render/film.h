// The film: every finished pass of a render, merged in pass order in double precision,
// whichever device rendered it. Per pixel it keeps the sum of samples (rgb, w: count)
// and the sum of their squares, from which the variance of the pixel's mean follows.
//
// Sums that do not depend on the order they were added in: every sample is rounded to a
// whole number of kFilmQuantum before it is added (to the radiance sums, the odd passes'
// and the surface layers'), so each sum is an integer number of quanta, which double
// precision adds exactly while it stays below 2^53 quanta (a pixel's samples summing to
// 2^29, about 5e8). Films of disjoint passes (chunks rendered apart, --passes) then merge
// into the same bits as one render of them all. The sums of squares are plain doubles
// (a sample's square is not a whole number of quanta): the variance agrees to rounding.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "image/image_io.h"

namespace fh {

// The film's sums of the odd passes per pixel, with two replicates: rgb and the sample count.
constexpr size_t kOddSumsPerPixel = 4;
// A pass's first-surface layers per pixel, after its radiance (kernels/aovs.h): albedo rgb,
// a flag, normal xyz, the camera ray's hit distance.
constexpr size_t kAovFloatsPerPixel = 8;
// The film's sums of them per pixel (Film::aovSum): albedo rgb, normal xyz, depth, hits.
constexpr size_t kAovSumsPerPixel = 8;
// The resolution samples are rounded to before the film adds them: 2^-24.
constexpr double kFilmQuantum = 1.0 / 16777216.0;

struct Film {
  Film() = default;
  // twoReplicates: even and odd passes come from independently scrambled sequences
  // (RenderParams::replicates), which estimatedRelMse compares. firstPass: the render's
  // pass the film starts at (a chunk's, --passes A:B; else 0).
  Film(int w, int h, bool surfaceAovs = false, bool twoReplicates = false, uint64_t firstPass = 0);

  // Adds pass `pass` (one the film does not hold): (rgb, 1) for each pixel it covers, in
  // order (every pixel, or those `covered` lists: an adaptive round's), as the device's pass
  // buffer holds them, then, for a film with surface AOVs, kAovFloatsPerPixel for each.
  void addPass(uint64_t pass, const std::vector<float>& samples, const std::vector<uint32_t>* covered = nullptr);
  // Adds the pass after the last one held (firstPass for an empty film).
  void addPass(const std::vector<float>& samples) { addPass(nextPass(), samples); }
  // Adds another film's passes: a chunk of the same render. Exact but for sumSq. Throws
  // fh::Error (a message to follow the other film's name) if the two differ in size or
  // layers, or hold a pass in common.
  void merge(const Film& other);

  // The passes the film holds, as ascending, disjoint, non-adjacent [begin, end) ranges.
  using PassRanges = std::vector<std::pair<uint64_t, uint64_t>>;
  const PassRanges& passRanges() const { return held_; }
  // For a film read back or summed from others: the passes its sums hold.
  void setPassRanges(PassRanges ranges);
  bool holds(uint64_t pass) const;
  // The ranges as text: "0:5, 8:12" (or "none").
  std::string describePasses() const;

  Image image() const;  // the mean per pixel
  // The image with --aovs layers beside it (albedo, normal, depth, variance, spp, in the
  // order given), named as compositors and denoisers read them (albedo.R, depth.Z).
  Image imageWithLayers(const std::vector<std::string>& layers) const;
  // The variance of the pixel's mean estimate, per channel (sample variance / count).
  std::array<double, 3> varianceOfMean(size_t pixel) const;
  // The image's expected relMSE against the converged image, estimated from the film alone:
  // each pixel's expected squared error over its neighbours' squared mean (the converged
  // value, judged apart from the pixel's own samples) plus relMSE's epsilon,
  // averaged like relMSE (image/error_metrics.h). The expected squared error of an unbiased
  // mean is its variance: with two replicates, from the difference of the even and odd
  // passes' means (unbiased, as the two are independent); else the sample variance / count,
  // which overstates the error of low-discrepancy samples (they are not independent).
  double estimatedRelMse() const;
  // The same estimate, robust to a few pixels: the median of its means over five interleaved
  // sets of pixels (a median of means). In a short render a method's rare bright samples
  // land in a few pixels, whose error then decides the mean, and which sets they fall in
  // decides little of the median; an error spread over many pixels moves each set's mean
  // alike. Where no pixel stands out it is about estimatedRelMse.
  double typicalRelMse() const;
  uint64_t passes() const { return passes_; }
  // The first pass held; for an empty film, the first it was made to hold.
  uint64_t firstPass() const { return held_.empty() ? firstPass_ : held_.front().first; }
  uint64_t nextPass() const { return held_.empty() ? firstPass_ : held_.back().second; }
  // Whether the film holds passes firstPass() .. nextPass() - 1 and no others.
  bool consecutive() const { return held_.size() <= 1; }
  double count(size_t pixel) const { return sum[4 * pixel + 3]; }
  // Samples over all pixels (every pixel's count: an adaptive render's differ).
  double samples() const;
  size_t pixels() const { return size_t(width) * size_t(height); }

  // The first-surface layers, means per pixel: albedo and normal over all samples (zero
  // where a sample saw nothing; the normal is not renormalized), depth over the samples that
  // hit something (kNoDepth where none did). Empty without surface AOVs.
  std::vector<float> albedo() const;
  std::vector<float> normal() const;
  std::vector<float> depth() const;
  bool hasSurfaceAovs() const { return !aovSum.empty(); }

  int width = 0, height = 0;
  // The scene's radiance per renderer radiance (render/radiance_unit.h) and its lengths per
  // renderer length (1 / Scene::worldScale): addPass records a pass's samples and depths in
  // the scene's units. Not saved: a film's sums are in the scene's units already.
  double radianceUnit = 1.0, depthUnit = 1.0;
  std::vector<double> sum, sumSq;
  // Per pixel: albedo rgb, normal xyz, depth, samples that hit (sums in pass order).
  std::vector<double> aovSum;
  // With two replicates: per pixel, the rgb sums of the odd passes and their sample count.
  std::vector<double> oddSum;
  // An adaptive render's film (render/adaptive.h): the pixels covered by the round its next
  // pass is in and by the round after it, both chosen before the film got here, so that a
  // render resumed from it goes on with them; null: not recorded (the first two rounds
  // cover every pixel).
  std::shared_ptr<const std::vector<uint32_t>> roundPixels, nextRoundPixels;

 private:
  std::vector<float> aovMean(size_t first) const;
  template <typename Add>
  void forEachPixelRelMse(Add add) const;
  uint64_t firstPass_ = 0, passes_ = 0;
  PassRanges held_;
};

// The depth of a pixel where nothing was hit (as Cycles writes its background's).
constexpr float kNoDepth = 1e10f;

}  // namespace fh
