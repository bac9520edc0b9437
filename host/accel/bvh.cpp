// Binned SAH build (32 bins, all three axes) and the collapse into 8-wide nodes.
#include "accel/bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "base/vec.h"

namespace fh {
namespace {

constexpr int kBins = 32;
constexpr unsigned kMaxLeaf = FH_MAX_LEAF_TRIANGLES;
// SAH costs relative to one box test. A leaf's triangles are tested eight at a time
// (TriangleBlock8), so a triangle costs a fraction of a box test and leaves fill up.
constexpr float kTraversalCost = 1.0f;
constexpr float kTriangleCost = 0.15f;

struct Box {
  float3 lo{INFINITY, INFINITY, INFINITY};
  float3 hi{-INFINITY, -INFINITY, -INFINITY};
  void grow(const float3& p) {
    lo = minv(lo, p);
    hi = maxv(hi, p);
  }
  void grow(const Box& b) {
    lo = minv(lo, b.lo);
    hi = maxv(hi, b.hi);
  }
  float area() const {
    if (lo[0] > hi[0]) return 0.f;
    const float3 e = hi - lo;
    return 2.f * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
  }
};

struct BinaryNode {
  Box box;
  int left = -1, right = -1;  // children when count == 0
  unsigned first = 0, count = 0;
};

class BinaryBuilder {
 public:
  BinaryBuilder(const Scene& scene) : boxes_(scene.triangleCount()), centroids_(scene.triangleCount()) {
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
      for (int k = 0; k < 3; ++k) boxes_[t].grow(scene.corner(t, k));
      centroids_[t] = (boxes_[t].lo + boxes_[t].hi) * 0.5f;
    }
    index_.resize(scene.triangleCount());
    for (size_t i = 0; i < index_.size(); ++i) index_[i] = unsigned(i);
  }

  std::vector<BinaryNode> build() {
    nodes_.reserve(2 * index_.size());
    nodes_.emplace_back();
    split(0, 0, unsigned(index_.size()));
    return std::move(nodes_);
  }

  const std::vector<unsigned>& order() const { return index_; }

 private:
  struct Split {
    int axis = -1;
    float position = 0.f;
    float cost = INFINITY;
  };

  Split findSplit(unsigned first, unsigned count, const Box& centroidBox, float parentArea) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      const float lo = centroidBox.lo[size_t(axis)], extent = centroidBox.hi[size_t(axis)] - lo;
      if (!(extent > 0.f)) continue;
      Box bins[kBins];
      unsigned counts[kBins] = {};
      const float scale = kBins / extent;
      for (unsigned i = first; i < first + count; ++i) {
        const unsigned t = index_[i];
        const int b = std::min(kBins - 1, int((centroids_[t][size_t(axis)] - lo) * scale));
        bins[b].grow(boxes_[t]);
        ++counts[b];
      }
      // Sweep from the right to get the right-side areas, then from the left.
      float rightArea[kBins];
      unsigned rightCount[kBins];
      Box acc;
      unsigned n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bins[b]);
        n += counts[b];
        rightArea[b] = acc.area();
        rightCount[b] = n;
      }
      acc = Box();
      n = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bins[b]);
        n += counts[b];
        if (n == 0 || rightCount[b + 1] == 0) continue;
        const float cost =
            kTraversalCost + kTriangleCost * (acc.area() * n + rightArea[b + 1] * rightCount[b + 1]) / parentArea;
        if (cost < best.cost) best = {axis, lo + (b + 1) / scale, cost};
      }
    }
    return best;
  }

  void makeLeaf(int node, unsigned first, unsigned count) {
    nodes_[size_t(node)].first = first;
    nodes_[size_t(node)].count = count;
  }

  void split(int node, unsigned first, unsigned count) {
    Box box, centroidBox;
    for (unsigned i = first; i < first + count; ++i) {
      box.grow(boxes_[index_[i]]);
      centroidBox.grow(centroids_[index_[i]]);
    }
    nodes_[size_t(node)].box = box;
    if (count == 1) return makeLeaf(node, first, count);

    const float area = std::max(box.area(), 1e-30f);
    const Split s = findSplit(first, count, centroidBox, area);
    unsigned mid = first;
    if (s.axis >= 0) {
      if (count <= kMaxLeaf && kTriangleCost * float(count) <= s.cost) return makeLeaf(node, first, count);
      auto* begin = index_.data() + first;
      mid = unsigned(std::partition(begin, begin + count,
                                    [&](unsigned t) { return centroids_[t][size_t(s.axis)] < s.position; }) -
                     index_.data());
    }
    if (mid == first || mid == first + count) {
      // All centroids coincide (or binning could not separate them).
      if (count <= kMaxLeaf) return makeLeaf(node, first, count);
      mid = first + count / 2;
    }
    const int left = int(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[size_t(node)].left = left;
    nodes_[size_t(node)].right = left + 1;
    split(left, first, mid - first);
    split(left + 1, mid, first + count - mid);
  }

  std::vector<Box> boxes_;
  std::vector<float3> centroids_;
  std::vector<unsigned> index_;
  std::vector<BinaryNode> nodes_;
};

class WideCollapser {
 public:
  WideCollapser(const std::vector<BinaryNode>& binary, const Scene& scene, const std::vector<unsigned>& order,
                Bvh& out)
      : binary_(binary), scene_(scene), order_(order), out_(out) {}

  void collapseRoot() {
    if (binary_[0].count > 0) {
      // A single-leaf tree still gets an inner root, so the root is never a leaf.
      out_.nodes.emplace_back();
      clearNode(out_.nodes[0]);
      setChild(0, 0, 0, 1);
      out_.stats.depth = 1;
      out_.stats.leaves = 1;
      return;
    }
    collapse(0, 1);
  }

 private:
  static void clearNode(gpu::Bvh8Node& n) { std::memset(&n, 0, sizeof n); }

  // The leaf's triangles [first, first + count) in BVH order, as one SoA block.
  int addBlock(unsigned first, unsigned count) {
    gpu::TriangleBlock8 block;
    std::memset(&block, 0, sizeof block);
    for (unsigned lane = 0; lane < 8; ++lane) {
      block.id[lane] = lane < count ? int(first + lane) : -1;
      if (lane >= count) continue;
      for (int k = 0; k < 3; ++k) {
        const float3 p = scene_.corner(order_[first + lane], k);
        for (int axis = 0; axis < 3; ++axis) block.v[k][axis][lane] = p[size_t(axis)];
      }
    }
    out_.blocks.push_back(block);
    return int(out_.blocks.size() - 1);
  }

  // Slot `slot` of wide node `wide` gets binary node `b`, whose subtree is at `depth`.
  void setChild(int wide, int slot, int b, int depth) {
    const BinaryNode& child = binary_[size_t(b)];
    int ref;
    if (child.count > 0) {
      ref = ~addBlock(child.first, child.count);
      ++out_.stats.leaves;
      out_.stats.depth = std::max(out_.stats.depth, depth);
    } else {
      ref = collapse(b, depth + 1);
    }
    gpu::Bvh8Node& n = out_.nodes[size_t(wide)];
    n.lo_x[slot] = child.box.lo[0];
    n.lo_y[slot] = child.box.lo[1];
    n.lo_z[slot] = child.box.lo[2];
    n.hi_x[slot] = child.box.hi[0];
    n.hi_y[slot] = child.box.hi[1];
    n.hi_z[slot] = child.box.hi[2];
    n.child[slot] = ref;
  }

  // Pulls grandchildren up (largest area first) until the node has 8 children.
  int collapse(int b, int depth) {
    std::vector<int> children = {binary_[size_t(b)].left, binary_[size_t(b)].right};
    while (children.size() < FH_BVH_WIDTH) {
      int best = -1;
      float bestArea = -1.f;
      for (size_t i = 0; i < children.size(); ++i) {
        const BinaryNode& c = binary_[size_t(children[i])];
        if (c.count == 0 && c.box.area() > bestArea) {
          bestArea = c.box.area();
          best = int(i);
        }
      }
      if (best < 0) break;
      const BinaryNode& expand = binary_[size_t(children[size_t(best)])];
      children[size_t(best)] = expand.left;
      children.push_back(expand.right);
    }
    const int wide = int(out_.nodes.size());
    out_.nodes.emplace_back();
    clearNode(out_.nodes.back());
    for (size_t i = 0; i < children.size(); ++i) setChild(wide, int(i), children[i], depth);
    return wide;
  }

  const std::vector<BinaryNode>& binary_;
  const Scene& scene_;
  const std::vector<unsigned>& order_;
  Bvh& out_;
};

}  // namespace

Bvh buildBvh(const Scene& scene) {
  const auto start = std::chrono::steady_clock::now();
  Bvh bvh;
  BinaryBuilder builder(scene);
  const std::vector<BinaryNode> binary = builder.build();
  bvh.order = builder.order();
  bvh.stats.binaryNodes = binary.size();

  WideCollapser(binary, scene, bvh.order, bvh).collapseRoot();
  bvh.stats.wideNodes = bvh.nodes.size();

  bvh.triangles.resize(12 * bvh.order.size());
  for (size_t k = 0; k < bvh.order.size(); ++k) {
    float* out = &bvh.triangles[12 * k];
    for (int c = 0; c < 3; ++c) {
      const float3 p = scene.corner(bvh.order[k], c);
      std::copy(p.begin(), p.end(), out + 4 * c);
      out[4 * c + 3] = 0.f;
    }
    std::memcpy(&out[3], &bvh.order[k], sizeof(unsigned));
  }
  bvh.stats.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

}  // namespace fh
