#include "render/merge_grid.h"

#include <cmath>
#include <cstring>

namespace fh {

float mergeRadius(float firstRadius, uint32_t pass) {
  constexpr double kAlpha = 0.75;
  return float(double(firstRadius) * std::pow(double(pass) + 1.0, (kAlpha - 1.0) / 2.0));
}

MergeGrid buildMergeGrid(const float* positions, const uint32_t* counts, unsigned paths, unsigned maxDepth,
                         float radius, const float lo[3]) {
  MergeGrid grid;
  for (int a = 0; a < 3; ++a) grid.lo[a] = lo[a];
  grid.inverseCell = 1.f / (2.f * radius);
  size_t vertices = 0;
  for (unsigned p = 0; p < paths; ++p) vertices += counts[p];
  size_t buckets = 1;
  while (buckets < vertices) buckets *= 2;
  grid.mask = uint32_t(buckets - 1);
  // Counting sort by bucket, stable in slot order.
  std::vector<uint32_t> bucketOf(vertices);
  grid.starts.assign(buckets + 1, 0);
  size_t n = 0;
  for (unsigned p = 0; p < paths; ++p)
    for (unsigned k = 0; k < counts[p]; ++k) {
      const float* position = positions + 4 * n;
      int cell[3];
      for (int a = 0; a < 3; ++a) cell[a] = int(std::floor((position[a] - grid.lo[a]) * grid.inverseCell));
      bucketOf[n] = mergeBucket(cell[0], cell[1], cell[2], grid.mask);
      ++grid.starts[bucketOf[n] + 1];
      ++n;
    }
  for (size_t b = 0; b < buckets; ++b) grid.starts[b + 1] += grid.starts[b];
  grid.filed.resize(4 * vertices);
  std::vector<uint32_t> next(grid.starts.begin(), grid.starts.end() - 1);
  n = 0;
  for (unsigned p = 0; p < paths; ++p)
    for (unsigned k = 0; k < counts[p]; ++k, ++n) {
      float* entry = &grid.filed[4 * size_t(next[bucketOf[n]]++)];
      std::memcpy(entry, positions + 4 * n, 3 * sizeof(float));
      const uint32_t slot = uint32_t(size_t(p) * maxDepth + k);
      std::memcpy(entry + 3, &slot, sizeof(float));
    }
  return grid;
}

}  // namespace fh
