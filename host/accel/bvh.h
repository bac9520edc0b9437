// The bounding volume hierarchy: a binary tree built with the binned surface area
// heuristic and spatial splits, collapsed into 8-wide nodes (kernels/types.h) for float8 traversal.
#pragma once
#include <cstddef>
#include <vector>

#include "kernels/types.h"
#include "scene/scene.h"

namespace fh {

struct BvhStats {
  size_t binaryNodes = 0;
  size_t wideNodes = 0;
  size_t leaves = 0;
  size_t references = 0;  // triangles in leaves: more than the scene's where spatial splits cut some
  int depth = 0;  // wide levels from the root to the deepest leaf
  double sahCost = 0.0;  // of the binary tree (bvh.cpp: sahCost), in box tests per ray
  // Of the 8-wide tree the kernels traverse, as its collapse plans it: 1 per wide node
  // visited and 1.2 per leaf block tested (eight triangles at 0.15), each weighted by its
  // box's area over the root's plus its volume over the root's (bvh.cpp: kVolumeWeight).
  double wideSahCost = 0.0;
  double buildSeconds = 0.0;
};

struct Bvh {
  std::vector<gpu::Bvh8Node> nodes;
  std::vector<gpu::TriangleBlock8> blocks;  // one per leaf, for the intersect kernels
  std::vector<float> triangles;  // 12 floats per triangle in BVH order: v0.xyz id, v1.xyz 0, v2.xyz 0
  std::vector<unsigned> order;   // order[k]: the file-order id of the k-th triangle in BVH order
  BvhStats stats;

  // Device memory of the structure the intersect kernels read (nodes and leaf blocks).
  size_t bytes() const { return nodes.size() * sizeof(gpu::Bvh8Node) + blocks.size() * sizeof(gpu::TriangleBlock8); }
  // Entries the traversal stack needs: each wide level defers up to 7 children.
  int traversalStack() const { return 7 * stats.depth + 1; }
};

struct BvhOptions {
  unsigned threads = 0;  // 0: every core; the tree is the same for any count
  // Spatial splits may add up to this many references per triangle (0: object splits only).
  float spatialSplitBudget = 0.5f;
};

Bvh buildBvh(const Scene& scene, BvhOptions options = {});

// Puts per-triangle data in BVH order: out[k] = in[order[k]] (stride values per triangle).
template <typename T>
std::vector<T> toBvhOrder(const std::vector<T>& in, const std::vector<unsigned>& order, size_t stride = 1) {
  std::vector<T> out(order.size() * stride);
  for (size_t k = 0; k < order.size(); ++k)
    for (size_t j = 0; j < stride; ++j) out[k * stride + j] = in[order[k] * stride + j];
  return out;
}

}  // namespace fh
