// Binned SAH build (32 bins, all three axes), with subtrees built in parallel, and the
// collapse into 8-wide nodes.
#include "accel/bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <future>
#include <thread>

#include "base/vec.h"

namespace fh {
namespace {

constexpr int kBins = 32;
constexpr unsigned kMaxLeaf = FH_MAX_LEAF_TRIANGLES;
// SAH costs relative to one box test. A leaf's triangles are tested eight at a time
// (TriangleBlock8), so a triangle costs a fraction of a box test and leaves fill up.
constexpr float kTraversalCost = 1.0f;
constexpr float kTriangleCost = 0.15f;

// Grown with plain comparisons (std::min/max), which compile inline: fminf/fmaxf, which
// must handle NaNs (scenes have none: the loader rejects them), were library calls on
// the build's hot path.
struct Box {
  float3 lo{INFINITY, INFINITY, INFINITY};
  float3 hi{-INFINITY, -INFINITY, -INFINITY};
  void grow(const float3& p) { grow(p, p); }
  void grow(const Box& b) { grow(b.lo, b.hi); }
  void grow(const float3& low, const float3& high) {
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], low[k]);
      hi[k] = std::max(hi[k], high[k]);
    }
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

// The triangles a build partitions: boxes and centroids by file-order id, and the ids in
// the order the build arranges them (each subtree owns a contiguous range).
struct Primitives {
  std::vector<Box> boxes;
  std::vector<float3> centroids;
  std::vector<unsigned> index;
};

// Boxes and centroids of every triangle, on `threads` threads.
Primitives gatherPrimitives(const Scene& scene, unsigned threads) {
  Primitives p;
  const size_t n = scene.triangleCount();
  p.boxes.resize(n);
  p.centroids.resize(n);
  p.index.resize(n);
  auto range = [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      for (int k = 0; k < 3; ++k) p.boxes[t].grow(scene.corner(t, k));
      p.centroids[t] = (p.boxes[t].lo + p.boxes[t].hi) * 0.5f;
      p.index[t] = unsigned(t);
    }
  };
  std::vector<std::thread> workers;
  for (unsigned w = 1; w < threads; ++w) workers.emplace_back(range, n * w / threads, n * (w + 1) / threads);
  range(0, n / threads);
  for (auto& w : workers) w.join();
  return p;
}

// Subtrees at least this large build their second child on a thread of its own (while the
// tree is shallower than parallelDepth): smaller ones cost less than starting a thread.
constexpr unsigned kParallelTriangles = 16384;

// A binary subtree over primitives' index range, root at node 0, children depth first
// (left subtree, then right). Large right subtrees are built concurrently by builders of
// their own and grafted in at the index a serial build gives them, so the tree is the same
// whatever the thread count.
class BinaryBuilder {
 public:
  BinaryBuilder(Primitives& primitives, int parallelDepth) : p_(primitives), parallelDepth_(parallelDepth) {}

  std::vector<BinaryNode> build(unsigned first, unsigned count, int depth = 0) {
    nodes_.reserve(2 * size_t(count));
    nodes_.emplace_back();
    split(0, first, count, depth);
    return std::move(nodes_);
  }

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
        const unsigned t = p_.index[i];
        const int b = std::min(kBins - 1, int((p_.centroids[t][size_t(axis)] - lo) * scale));
        bins[b].grow(p_.boxes[t]);
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

  void split(int node, unsigned first, unsigned count, int depth) {
    Box box, centroidBox;
    for (unsigned i = first; i < first + count; ++i) {
      box.grow(p_.boxes[p_.index[i]]);
      centroidBox.grow(p_.centroids[p_.index[i]]);
    }
    nodes_[size_t(node)].box = box;
    if (count == 1) return makeLeaf(node, first, count);

    const float area = std::max(box.area(), 1e-30f);
    const Split s = findSplit(first, count, centroidBox, area);
    unsigned mid = first;
    if (s.axis >= 0) {
      if (count <= kMaxLeaf && kTriangleCost * float(count) <= s.cost) return makeLeaf(node, first, count);
      auto* begin = p_.index.data() + first;
      mid = unsigned(std::partition(begin, begin + count,
                                    [&](unsigned t) { return p_.centroids[t][size_t(s.axis)] < s.position; }) -
                     p_.index.data());
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
    const unsigned rightCount = first + count - mid;
    if (depth < parallelDepth_ && rightCount >= kParallelTriangles) {
      // The two children own disjoint ranges of the index: the right one on another thread.
      auto right = std::async(std::launch::async, [this, mid, rightCount, depth] {
        return BinaryBuilder(p_, parallelDepth_).build(mid, rightCount, depth + 1);
      });
      split(left, first, mid - first, depth + 1);
      graft(left + 1, right.get());
    } else {
      split(left, first, mid - first, depth + 1);
      split(left + 1, mid, rightCount, depth + 1);
    }
  }

  // Puts a subtree built on its own at `node` (its root) and after the nodes so far (its
  // other nodes), where a serial build numbers them.
  void graft(int node, std::vector<BinaryNode> subtree) {
    const int base = int(nodes_.size()) - 1;  // subtree node i > 0 goes to base + i
    for (BinaryNode& n : subtree)
      if (n.count == 0) {
        n.left += base;
        n.right += base;
      }
    nodes_[size_t(node)] = subtree[0];
    nodes_.insert(nodes_.end(), subtree.begin() + 1, subtree.end());
  }

  Primitives& p_;
  int parallelDepth_;
  std::vector<BinaryNode> nodes_;
};

// The surface area heuristic's cost of a binary tree (kTraversalCost per node visited,
// kTriangleCost per triangle tested, each weighted by its box's area over the root's): the
// build's quality, comparable between builders.
double sahCost(const std::vector<BinaryNode>& nodes) {
  const double root = std::max(double(nodes[0].box.area()), 1e-30);
  double cost = 0.0;
  for (const BinaryNode& n : nodes)
    cost += double(n.box.area()) / root * (n.count == 0 ? kTraversalCost : kTriangleCost * double(n.count));
  return cost;
}

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

Bvh buildBvh(const Scene& scene, unsigned threads) {
  const auto start = std::chrono::steady_clock::now();
  // FREDHOLM_BVH_THREADS caps the default (bench/RESULTS.md compares thread counts).
  const char* cap = std::getenv("FREDHOLM_BVH_THREADS");
  if (threads == 0 && cap && *cap) threads = unsigned(std::max(1, std::atoi(cap)));
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  Bvh bvh;
  Primitives primitives = gatherPrimitives(scene, threads);
  // Levels that fork: enough subtrees for every thread, and some over for uneven splits.
  int parallelDepth = 0;
  while (threads > 1 && (1u << parallelDepth) < 4 * threads) ++parallelDepth;
  const std::vector<BinaryNode> binary =
      BinaryBuilder(primitives, parallelDepth).build(0, unsigned(primitives.index.size()));
  bvh.order = std::move(primitives.index);
  bvh.stats.binaryNodes = binary.size();
  bvh.stats.sahCost = sahCost(binary);

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
