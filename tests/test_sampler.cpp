// The pixel sampler on the device (kernels/sampler.h): a pixel's first 2^k samples of a 2D
// dimension form a (0,k,2)-net (one point in every elementary interval of area 2^-k) and
// those of a 1D dimension one point per interval of length 2^-k; a given sample, across
// pixels, is uniform (chi-square); dimension pairs and seeds are uncorrelated.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "accel/ray_caster.h"
#include "device/kernel_sources.h"
#include "device/program.h"
#include "test_support.h"

namespace fh {
namespace {

const char* kTestKernels = R"CL(
__kernel void draw(uint seed, uint pixel_count, uint dimension, uint one_d, uint replicates, __global float2* out) {
  const uint i = get_global_id(0);
  const PixelSampler s = pixel_sampler(seed, i, pixel_count, replicates);
  const lvec2 u = sample_2d(&s, dimension);
  out[i] = one_d ? (float2)(sample_1d(&s, dimension), 0.0f) : (float2)(u.x, u.y);
}
)CL";

class PixelSamplerOnDevice : public ::testing::Test {
 protected:
  DeviceContext dc{selectDevices(listDevices(), "").front()};
  cl::Program program =
      buildProgramFromSource(dc.context, dc.info.device, assembleKernelSources({"sampler.h"}) + kTestKernels, "");

  // Samples 0 .. passes-1 of every pixel: result[pass * pixels + pixel].
  std::vector<float> draw(unsigned seed, unsigned pixels, unsigned passes, unsigned dimension, bool oneD = false,
                          unsigned replicates = 1) {
    const size_t n = size_t(pixels) * passes;
    cl::Buffer out = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, n * 8, "samples");
    cl::Kernel k = createKernel(program, "draw");
    setKernelArgs(k, seed, pixels, dimension, cl_uint(oneD), cl_uint(replicates), out);
    FH_CL(dc.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NDRange(64)));
    std::vector<float> v(n * 2);
    FH_CL(dc.queue.enqueueReadBuffer(out, CL_TRUE, 0, n * 8, v.data()));
    return v;
  }
};

TEST_F(PixelSamplerOnDevice, EveryPowerOfTwoPrefixIsANet) {
  const unsigned pixels = 64, passes = 256;
  for (unsigned dimension : {0u, 4u, 13u, 0x7fff0000u}) {
    const std::vector<float> v = draw(7, pixels, passes, dimension);
    const std::vector<float> w = draw(7, pixels, passes, dimension, true);
    for (unsigned pixel : {0u, 1u, 37u, 63u})
      for (unsigned k : {2u, 4u, 6u, 8u}) {
        const unsigned n = 1u << k;
        for (unsigned a = 0; a <= k; ++a) {  // cells of 2^-a by 2^-(k - a)
          std::set<unsigned> cells;
          for (unsigned s = 0; s < n; ++s) {
            const size_t i = 2 * (size_t(s) * pixels + pixel);
            cells.insert(unsigned(v[i] * float(1u << a)) * (1u << (k - a)) + unsigned(v[i + 1] * float(1u << (k - a))));
          }
          EXPECT_EQ(cells.size(), n) << "dimension " << dimension << " pixel " << pixel << " 2^" << k << " split " << a;
        }
        std::set<unsigned> intervals;
        for (unsigned s = 0; s < n; ++s) intervals.insert(unsigned(w[2 * (size_t(s) * pixels + pixel)] * float(n)));
        EXPECT_EQ(intervals.size(), n) << "1D dimension " << dimension << " pixel " << pixel << " 2^" << k;
      }
  }
}

// Two replicates (a noise target): the even passes are the one-sequence sampler's first
// passes, the odd ones a sequence of their own, each a net, and the two are uncorrelated
// across pixels (independent scramblings), which is what makes their difference an
// unbiased error estimate (host/render/film.h).
TEST_F(PixelSamplerOnDevice, TwoReplicatesAreTwoIndependentNets) {
  const unsigned pixels = 4096, passes = 64, dimension = 4;
  const std::vector<float> one = draw(5, pixels, passes / 2, dimension);
  const std::vector<float> two = draw(5, pixels, passes, dimension, false, 2);
  auto at = [&](const std::vector<float>& v, unsigned pass, unsigned pixel, int axis) {
    return v[2 * (size_t(pass) * pixels + pixel) + size_t(axis)];
  };
  for (unsigned pass = 0; pass < passes / 2; ++pass)
    for (unsigned pixel : {0u, 9u, 4095u}) ASSERT_EQ(at(two, 2 * pass, pixel, 0), at(one, pass, pixel, 0));
  for (unsigned replicate = 0; replicate < 2; ++replicate)
    for (unsigned pixel : {1u, 77u}) {
      std::set<unsigned> cells;  // 32 points in 32 cells of 1/4 x 1/8
      for (unsigned j = 0; j < passes / 2; ++j)
        cells.insert(unsigned(at(two, 2 * j + replicate, pixel, 0) * 4.f) * 8u +
                     unsigned(at(two, 2 * j + replicate, pixel, 1) * 8.f));
      EXPECT_EQ(cells.size(), passes / 2) << "replicate " << replicate << " pixel " << pixel;
    }
  // Correlation of the replicates' first samples across pixels: ~N(0, 1/sqrt(pixels)).
  double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
  for (unsigned p = 0; p < pixels; ++p) {
    const double x = at(two, 0, p, 0), y = at(two, 1, p, 0);
    sx += x, sy += y, sxy += x * y, sxx += x * x, syy += y * y;
  }
  const double n = pixels, r = (sxy / n - sx * sy / (n * n)) /
                               std::sqrt((sxx / n - sx * sx / (n * n)) * (syy / n - sy * sy / (n * n)));
  EXPECT_LT(std::fabs(r), 4.0 / std::sqrt(n));
}

// A pixel's first two samples lie in opposite halves of every dimension (the net), but
// where in each half is random: their difference, across pixels, is spread out. Sobol'
// points with the index shuffled but the values not scrambled (a planted bug once: unbiased, so no
// other test saw it) put every pixel's second sample exactly half a unit from its first.
TEST_F(PixelSamplerOnDevice, APixelsFirstTwoSamplesAreNotAFixedDistanceApart) {
  const unsigned pixels = 16384;
  for (bool oneD : {false, true}) {
    const std::vector<float> v = draw(11, pixels, 2, 6, oneD);
    for (int axis = 0; axis < (oneD ? 1 : 2); ++axis) {
      size_t nearHalf = 0;
      for (unsigned p = 0; p < pixels; ++p) {
        const double d = std::fabs(double(v[2 * (size_t(pixels) + p) + size_t(axis)]) - v[2 * size_t(p) + size_t(axis)]);
        nearHalf += std::fabs(d - 0.5) < 1.0 / 256;
      }
      // The difference of two uniform points in the two halves has density 2 at 1/2: about
      // 1.6 % of pixels fall within 1/256 of it.
      EXPECT_LT(double(nearHalf) / pixels, 0.05) << (oneD ? "1D" : "2D") << " axis " << axis;
    }
  }
}

// Each sample index, over many pixels, is uniform in the square: the scrambling is random
// per pixel, which is what keeps the estimator unbiased.
TEST_F(PixelSamplerOnDevice, EachSampleIsUniformAcrossPixels) {
  const unsigned pixels = 16384, passes = 5, grid = 16;
  const std::vector<float> v = draw(3, pixels, passes, 8);
  for (unsigned pass = 0; pass < passes; ++pass) {
    std::vector<double> count(grid * grid, 0.0);
    for (unsigned p = 0; p < pixels; ++p) {
      const size_t i = 2 * (size_t(pass) * pixels + p);
      count[unsigned(v[i] * grid) * grid + unsigned(v[i + 1] * grid)] += 1.0;
    }
    const double expected = double(pixels) / (grid * grid);
    double chi2 = 0;
    for (double c : count) chi2 += (c - expected) * (c - expected) / expected;
    // 255 degrees of freedom: mean 255, sd 22.6; the bound is about p = 1e-4.
    EXPECT_LT(chi2, 255 + 3.9 * std::sqrt(2 * 255.0)) << "pass " << pass;
  }
}

// Two dimension pairs of one pixel (shuffled independently), and one dimension under two
// seeds, are uncorrelated: |r| below 4 standard errors of a zero correlation.
TEST_F(PixelSamplerOnDevice, DimensionsAndSeedsAreUncorrelated) {
  const unsigned pixels = 256, passes = 64;
  const size_t n = size_t(pixels) * passes;
  auto correlation = [&](const std::vector<float>& a, const std::vector<float>& b) {
    double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < n; ++i) ma += a[2 * i] / double(n), mb += b[2 * i] / double(n);
    for (size_t i = 0; i < n; ++i) {
      const double da = a[2 * i] - ma, db = b[2 * i] - mb;
      sab += da * db, saa += da * da, sbb += db * db;
    }
    return sab / std::sqrt(saa * sbb);
  };
  const double bound = 4.0 / std::sqrt(double(n));
  EXPECT_LT(std::fabs(correlation(draw(1, pixels, passes, 0), draw(1, pixels, passes, 4))), bound);
  EXPECT_LT(std::fabs(correlation(draw(1, pixels, passes, 0), draw(2, pixels, passes, 0))), bound);
  EXPECT_LT(std::fabs(correlation(draw(1, pixels, passes, 2, true), draw(1, pixels, passes, 3, true))), bound);
}

}  // namespace
}  // namespace fh
