// Merging passes and reading the film out.
#include "render/film.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"
#include "image/error_metrics.h"

namespace fh {

namespace {

// v rounded to a whole number of film quanta.
double quantized(float v) { return std::nearbyint(double(v) / kFilmQuantum) * kFilmQuantum; }

void addEach(std::vector<double>& to, const std::vector<double>& from) {
  for (size_t i = 0; i < to.size(); ++i) to[i] += from[i];
}

}  // namespace

Film::Film(int w, int h, bool surfaceAovs, bool twoReplicates, uint64_t firstPass)
    : width(w), height(h), sum(pixels() * 4, 0.0), sumSq(pixels() * 4, 0.0),
      aovSum(surfaceAovs ? pixels() * kAovSumsPerPixel : 0, 0.0),
      oddSum(twoReplicates ? pixels() * kOddSumsPerPixel : 0, 0.0), firstPass_(firstPass) {}

void Film::merge(const Film& other) {
  if (other.width != width || other.height != height || other.aovSum.size() != aovSum.size() ||
      other.oddSum.size() != oddSum.size())
    throw Error("is not a film of the same size and layers");
  PassRanges ranges = held_;
  ranges.insert(ranges.end(), other.held_.begin(), other.held_.end());
  std::sort(ranges.begin(), ranges.end());
  for (size_t i = 1; i < ranges.size(); ++i)
    if (ranges[i].first < ranges[i - 1].second)
      throw Error("shares passes (" + std::to_string(ranges[i].first) + ":" +
                  std::to_string(std::min(ranges[i].second, ranges[i - 1].second)) +
                  ") with the film it joins; each pass may be merged once");
  addEach(sum, other.sum);
  addEach(sumSq, other.sumSq);
  addEach(aovSum, other.aovSum);
  addEach(oddSum, other.oddSum);
  firstPass_ = std::min(firstPass_, other.firstPass_);
  setPassRanges(ranges);
}

void Film::setPassRanges(PassRanges ranges) {
  std::sort(ranges.begin(), ranges.end());
  held_.clear();
  passes_ = 0;
  for (const auto& [begin, end] : ranges) {
    if (begin >= end) continue;
    if (!held_.empty() && begin <= held_.back().second) held_.back().second = std::max(held_.back().second, end);
    else held_.emplace_back(begin, end);
  }
  for (const auto& [begin, end] : held_) passes_ += end - begin;
}

bool Film::holds(uint64_t pass) const {
  for (const auto& [begin, end] : held_)
    if (pass >= begin && pass < end) return true;
  return false;
}

std::string Film::describePasses() const {
  std::string d;
  for (const auto& [begin, end] : held_)
    d += (d.empty() ? "" : ", ") + std::to_string(begin) + ":" + std::to_string(end);
  return d.empty() ? "none" : d;
}

void Film::addPass(uint64_t pass, const std::vector<float>& samples, const std::vector<uint32_t>* covered) {
  const size_t count = covered ? covered->size() : pixels();
  const bool odd = !oddSum.empty() && pass % 2 == 1;
  const float* aovs = samples.data() + 4 * count;
  for (size_t i = 0; i < count; ++i) {
    const size_t p = covered ? (*covered)[i] : i;
    for (size_t c = 0; c < 4; ++c) {
      const double v = quantized(samples[4 * i + c]) * (c == 3 ? 1.0 : radianceUnit);  // a power of two: exact
      sum[4 * p + c] += v;
      if (c != 3) sumSq[4 * p + c] += v * v;
      if (odd) oddSum[kOddSumsPerPixel * p + c] += v;
    }
    if (!hasSurfaceAovs()) continue;
    const float* in = aovs + kAovFloatsPerPixel * i;  // albedo rgb, flag, normal xyz, distance
    double* out = &aovSum[kAovSumsPerPixel * p];
    for (size_t c = 0; c < 3; ++c) {
      out[c] += quantized(in[c]);
      out[3 + c] += quantized(in[4 + c]);
    }
    if (in[7] > 0.f) {
      out[6] += quantized(in[7]) * depthUnit;
      out[7] += 1.0;
    }
  }
  held_.emplace_back(pass, pass + 1);
  setPassRanges(held_);
}

namespace {

// Per pixel and channel, the mean of the pixel's neighbours' means (up to 8, those with
// samples); the pixel's own mean where none has any. Rows are asked for in order from the
// top; three rows of pixel means are kept, summed down each column, then across: a few
// additions per pixel, as the estimate is taken after every merged pass.
class NeighbourMeans {
 public:
  explicit NeighbourMeans(const Film& film)
      : film_(film), width_(size_t(film.width)), own_(3 * width_), column_(width_), means_(3 * width_) {}

  const double* row(size_t y) {
    if (y == 0) fillOwn(0);
    if (y + 1 < size_t(film_.height)) fillOwn(y + 1);
    for (size_t x = 0; x < width_; ++x) {
      column_[x] = {};
      for (size_t r = y == 0 ? 0 : y - 1; r <= y + 1 && r < size_t(film_.height); ++r) add(column_[x], own(r)[x]);
    }
    for (size_t x = 0; x < width_; ++x) {
      Mean block = column_[x];
      if (x > 0) add(block, column_[x - 1]);
      if (x + 1 < width_) add(block, column_[x + 1]);
      const Mean& self = own(y)[x];
      const double n = block[3] - self[3];
      for (size_t c = 0; c < 3; ++c) means_[3 * x + c] = n > 0 ? (block[c] - self[c]) / n : self[c];
    }
    return means_.data();
  }

 private:
  using Mean = std::array<double, 4>;  // rgb, and 1 where the pixel has samples (else all 0)
  static void add(Mean& to, const Mean& v) {
    for (size_t k = 0; k < 4; ++k) to[k] += v[k];
  }
  Mean* own(size_t y) { return own_.data() + (y % 3) * width_; }
  void fillOwn(size_t y) {
    for (size_t x = 0; x < width_; ++x) {
      const size_t p = y * width_ + x;
      const double n = film_.count(p);
      own(y)[x] = n > 0 ? Mean{film_.sum[4 * p] / n, film_.sum[4 * p + 1] / n, film_.sum[4 * p + 2] / n, 1.0} : Mean{};
    }
  }

  const Film& film_;
  size_t width_;
  std::vector<Mean> own_, column_;
  std::vector<double> means_;
};

}  // namespace

// Calls add(pixel, e) with each pixel's share of the estimated relMSE: its channels' expected
// squared errors over the converged value squared plus relMSE's epsilon, summed.
template <typename Add>
void Film::forEachPixelRelMse(Add add) const {
  // relMSE divides by the converged value; the pixel's own mean stands in for it badly: a
  // rare bright sample raises both the pixel's error and its mean, so the two cancel and the
  // estimate runs low where such samples dominate. The neighbours' means do not depend on
  // the pixel's samples (bench/RESULTS.md, "--noise").
  NeighbourMeans neighbours(*this);
  const double* converged = nullptr;  // the row's, 3 per pixel
  for (size_t p = 0; p < pixels(); ++p) {
    if (p % size_t(width) == 0) converged = neighbours.row(p / size_t(width));
    const double n = count(p);
    if (n <= 0) continue;
    // The mean of nEven and nOdd samples: its variance is D^2 nEven nOdd / n^2 in
    // expectation, D the difference of the halves' means (each half's variance proportional
    // to 1 / count). A pixel's counts are its own: an adaptive render's passes skip pixels.
    const double nOdd = oddSum.empty() ? 0.0 : oddSum[kOddSumsPerPixel * p + 3], nEven = n - nOdd;
    const bool replicated = nOdd > 0 && nEven > 0;
    const std::array<double, 3> variance = varianceOfMean(p);
    double share = 0.0;
    for (size_t c = 0; c < 3; ++c) {
      double error = variance[c];
      if (replicated) {
        const double odd = oddSum[kOddSumsPerPixel * p + c], d = (sum[4 * p + c] - odd) / nEven - odd / nOdd;
        error = d * d * nEven * nOdd / (n * n);
      }
      const double value = converged[3 * (p % size_t(width)) + c];
      share += error / (value * value + kRelMseEpsilon);
    }
    add(p, share);
  }
}

double Film::estimatedRelMse() const {
  double total = 0.0;
  forEachPixelRelMse([&](size_t, double share) { total += share; });
  return pixels() ? total / double(3 * pixels()) : 0.0;
}

double Film::typicalRelMse() const {
  // Pixel (x, y) is in set (x + 2y) mod 5: any five pixels in a row or a column fall in
  // five different sets, so each set samples every region of the image alike.
  constexpr size_t kSets = 5;
  const auto setOf = [&](size_t p) { return (p % size_t(width) + 2 * (p / size_t(width))) % kSets; };
  std::array<double, kSets> total{}, pixelsIn{};
  forEachPixelRelMse([&](size_t p, double share) { total[setOf(p)] += share; });
  for (size_t p = 0; p < pixels(); ++p) pixelsIn[setOf(p)] += 1.0;
  std::vector<double> means;
  for (size_t k = 0; k < kSets; ++k)
    if (pixelsIn[k] > 0) means.push_back(total[k] / (3.0 * pixelsIn[k]));
  if (means.empty()) return 0.0;
  std::sort(means.begin(), means.end());
  const size_t mid = means.size() / 2;
  return means.size() % 2 ? means[mid] : (means[mid - 1] + means[mid]) / 2;
}

double Film::samples() const {
  double total = 0.0;
  for (size_t p = 0; p < pixels(); ++p) total += count(p);
  return total;
}

// Channels first .. first + 2 of the layer sums, over each pixel's samples.
std::vector<float> Film::aovMean(size_t first) const {
  std::vector<float> v;
  for (size_t p = 0; p < pixels() && hasSurfaceAovs(); ++p)
    for (size_t c = 0; c < 3; ++c)
      v.push_back(count(p) > 0 ? float(aovSum[kAovSumsPerPixel * p + first + c] / count(p)) : 0.f);
  return v;
}

std::vector<float> Film::albedo() const { return aovMean(0); }
std::vector<float> Film::normal() const { return aovMean(3); }

std::vector<float> Film::depth() const {
  std::vector<float> v;
  for (size_t p = 0; p < pixels() && hasSurfaceAovs(); ++p) {
    const double hits = aovSum[kAovSumsPerPixel * p + 7];
    v.push_back(hits > 0 ? float(aovSum[kAovSumsPerPixel * p + 6] / hits) : kNoDepth);
  }
  return v;
}

Image Film::image() const {
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.resize(pixels() * 3);
  for (size_t p = 0; p < pixels(); ++p)
    for (size_t c = 0; c < 3; ++c) img.rgb[3 * p + c] = count(p) > 0 ? float(sum[4 * p + c] / count(p)) : 0.f;
  return img;
}

std::array<double, 3> Film::varianceOfMean(size_t p) const {
  const double n = count(p);
  std::array<double, 3> v{0, 0, 0};
  if (n < 2) return v;
  for (size_t c = 0; c < 3; ++c) {
    const double mean = sum[4 * p + c] / n;
    const double sampleVariance = std::max(0.0, (sumSq[4 * p + c] - n * mean * mean) / (n - 1));
    v[c] = sampleVariance / n;
  }
  return v;
}

Image Film::imageWithLayers(const std::vector<std::string>& layers) const {
  Image image = this->image();
  for (const std::string& name : layers) {
    ImageLayer layer{name, {}, {}};
    if (name == "albedo") {
      layer.channels = {"R", "G", "B"};
      layer.values = albedo();
    } else if (name == "normal") {
      layer.channels = {"X", "Y", "Z"};
      layer.values = normal();
    } else if (name == "depth") {
      layer.channels = {"Z"};
      layer.values = depth();
    } else if (name == "variance") {
      layer.channels = {"R", "G", "B"};
      for (size_t p = 0; p < pixels(); ++p)
        for (double v : varianceOfMean(p)) layer.values.push_back(float(v));
    } else {  // spp
      layer.channels = {"Y"};
      for (size_t p = 0; p < pixels(); ++p) layer.values.push_back(float(count(p)));
    }
    image.layers.push_back(std::move(layer));
  }
  return image;
}

}  // namespace fh
