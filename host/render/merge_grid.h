// Vertex merging's lookup structure (--method vcm, kernels/bdpt.cl): the light vertices of a
// launch filed in a hash grid of cells 2r wide, so that a camera vertex finds every light
// vertex within r in the eight cells around it. Built on the host, in slot order within
// each cell, so a camera vertex sums its merges in the same order on every device.
#pragma once
#include <cstdint>
#include <vector>

namespace fh {

// The merging radius of global pass `pass` (0 first): r0 (pass + 1)^((alpha - 1) / 2) with
// alpha = 3/4 (Knaus and Zwicker 2011): each pass's radius smaller by just enough that the
// bias goes to zero while the variance a pass adds does not grow without bound.
float mergeRadius(float firstRadius, uint32_t pass);

struct MergeGrid {
  float lo[3] = {0, 0, 0};  // the grid's corner
  float inverseCell = 0;    // 1 / a cell's width, 2 r (kernels/bdpt.cl merge_cell)
  uint32_t mask = 0;        // buckets - 1
  // Bucket b's vertices are filed[starts[b]] .. filed[starts[b + 1] - 1], a float4 each:
  // the position and (w) the bits of its slot.
  std::vector<uint32_t> starts;
  std::vector<float> filed;
};

// The grid of radius r over `paths` light paths of `maxDepth` vertex slots each, vertex k
// of path p at slot p maxDepth + k, `counts[p]` of them stored; `positions` holds them one
// float4 (xyz) each, path after path. lo: a corner below every vertex (the grid is
// unbounded; lo only keeps cell indices small).
MergeGrid buildMergeGrid(const float* positions, const uint32_t* counts, unsigned paths, unsigned maxDepth,
                         float radius, const float lo[3]);

// The bucket of cell (i, j, k) under mask (kernels/bdpt.cl merge_bucket hashes alike).
inline uint32_t mergeBucket(int i, int j, int k, uint32_t mask) {
  return ((uint32_t(i) * 73856093u) ^ (uint32_t(j) * 19349663u) ^ (uint32_t(k) * 83492791u)) & mask;
}

}  // namespace fh
