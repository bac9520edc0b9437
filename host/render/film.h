// The film: every finished pass of a render, merged in pass order in double precision,
// whichever device rendered it. Per pixel it keeps the sum of samples (rgb, w: count)
// and the sum of their squares, from which the variance of the pixel's mean follows.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "image/image_io.h"

namespace fh {

// A pass's first-surface layers per pixel, after its radiance (kernels/aovs.h): albedo rgb,
// a flag, normal xyz, the camera ray's hit distance.
constexpr size_t kAovFloatsPerPixel = 8;
// The film's sums of them per pixel (Film::aovSum): albedo rgb, normal xyz, depth, hits.
constexpr size_t kAovSumsPerPixel = 8;

struct Film {
  Film() = default;
  // twoReplicates: even and odd passes come from independently scrambled sequences
  // (RenderParams::replicates), which estimatedRelMse compares.
  Film(int w, int h, bool surfaceAovs = false, bool twoReplicates = false);

  // Adds one pass: per pixel (rgb, 1), pixel-major, as the device's pass buffer holds it,
  // then, for a film with surface AOVs, kAovFloatsPerPixel per pixel.
  void addPass(const std::vector<float>& samples);

  Image image() const;  // the mean per pixel
  // The variance of the pixel's mean estimate, per channel (sample variance / count).
  std::array<double, 3> varianceOfMean(size_t pixel) const;
  // The image's expected relMSE against the converged image, estimated from the film alone:
  // each pixel's expected squared error over its squared mean plus relMSE's epsilon,
  // averaged like relMSE (image/error_metrics.h). The expected squared error of an unbiased
  // mean is its variance: with two replicates, from the difference of the even and odd
  // passes' means (unbiased, as the two are independent); else the sample variance / count,
  // which overstates the error of low-discrepancy samples (they are not independent).
  double estimatedRelMse() const;
  uint64_t passes() const { return passes_; }
  // A film read back from a checkpoint holds passes 0 .. passes - 1.
  void resumeAt(uint64_t passes) { passes_ = passes; }
  double count(size_t pixel) const { return sum[4 * pixel + 3]; }
  size_t pixels() const { return size_t(width) * size_t(height); }

  // The first-surface layers, means per pixel: albedo and normal over all samples (zero
  // where a sample saw nothing; the normal is not renormalized), depth over the samples that
  // hit something (kNoDepth where none did). Empty without surface AOVs.
  std::vector<float> albedo() const;
  std::vector<float> normal() const;
  std::vector<float> depth() const;
  bool hasSurfaceAovs() const { return !aovSum.empty(); }

  int width = 0, height = 0;
  std::vector<double> sum, sumSq;
  // Per pixel: albedo rgb, normal xyz, depth, samples that hit (sums in pass order).
  std::vector<double> aovSum;
  // With two replicates: per pixel, the rgb sums of the odd passes.
  std::vector<double> oddSum;

 private:
  std::vector<float> aovMean(size_t first) const;
  uint64_t passes_ = 0;
};

// The depth of a pixel where nothing was hit (as Cycles writes its background's).
constexpr float kNoDepth = 1e10f;

}  // namespace fh
