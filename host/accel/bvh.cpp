// Binned SAH build with spatial splits (Stich, Friedrich and Dietrich, "Spatial Splits in
// Bounding Volume Hierarchies", HPG 2009), subtrees built in parallel, and the collapse into
// 8-wide nodes.
#include "accel/bvh.h"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <future>
#include <limits>
#include <string>
#include <thread>

#include "base/error.h"
#include "base/vec.h"

namespace fh {
namespace {

constexpr int kBins = 32;
constexpr int kSpatialBins = 32;
constexpr int kMaxBins = std::max(kBins, kSpatialBins);
constexpr unsigned kMaxLeaf = FH_MAX_LEAF_TRIANGLES;
// SAH costs relative to one box test. A leaf's triangles are tested eight at a time
// (TriangleBlock8), so a triangle costs a fraction of a box test and leaves fill up.
constexpr float kTraversalCost = 1.0f;
constexpr float kTriangleCost = 0.15f;
// Testing a leaf block costs the same however many of its eight lanes are filled
// (WideCollapser chooses the 8-wide tree with it).
constexpr float kLeafBlockCost = kTriangleCost * float(kMaxLeaf);
// The binary builder counts a child's triangles in groups of this many (see groupedCount).
constexpr size_t kCountGroup = kMaxLeaf / 2;
// Spatial splits are tried where the best object split's children overlap by more than
// this fraction of the root's area (Stich et al.'s alpha, who use 1e-5): below it they gain
// little, and trying them costs a clipping pass over the node's references.
constexpr float kOverlapToTrySpatial = 1e-2f;
// A spatial split is taken only where it costs this fraction less than the best object
// split. The greedy estimate (children as leaves) overrates small gains near the root of a
// big tree: on the 1M-triangle scene, splits that won narrowly there left the whole
// tree worse. Where spatial splits pay (long overlapping triangles), they win by far more.
constexpr float kSpatialSplitGain = 0.05f;
// Secondary rays start on the scene's surfaces, inside its boxes, and a ray visits every box
// it starts in, which the area ratio alone does not count: a leaf whose box spans a room
// (a floor, a back wall and a wall gathered in one block) is visited by nearly every ray in
// the room, while the walls' flat boxes apart are visited only by the rays that reach them.
// The wide tree's plan adds this weight times a box's share of the scene's volume to its
// share of the area (ray origins taken as spread through the volume, in the spirit of
// Fabianowski, Fowler and Dingliana, "A Cost Metric for Scene-Interior Ray Origins",
// Eurographics 2009). Deep in a mesh, boxes are small and the term vanishes.
constexpr float kVolumeWeight = 1.0f;
// So that the plan may keep such primitives apart, the binary builder splits nodes holding
// at least this share of the scene's volume down to leaves of kRoomyLeaf references
// (the plan may gather them again); elsewhere its leaves take up to kMaxLeaf.
constexpr float kRoomyVolume = 1e-2f;
constexpr unsigned kRoomyLeaf = 2;

// Any finite scene must build, from triangles a few 1e-38 wide to coordinates near FLT_MAX,
// so what the builder derives from the floats it is given (extents, areas, volumes,
// centroids, bin indices and planes, SAH costs) is computed in double, which holds every
// such value of float inputs without overflow or underflow: a float extent overflows to inf
// past FLT_MAX, an area past 1.8e19 and underflows below 1e-19, a centroid's sum lo + hi
// overflows past FLT_MAX / 2. The boxes themselves stay float (the kernels read them), each
// the exact bound of floats or rounded outwards (edgeCrossing).
constexpr double kMinArea = std::numeric_limits<double>::min();  // floor of a parent's area (a point's is 0)

// Grown with plain comparisons (std::min/max), which compile inline: fminf/fmaxf, which
// must handle NaNs (scenes have none: the loader rejects them, buildBvh checks), were
// library calls on the build's hot path.
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
  bool empty() const { return lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]; }
  double extent(size_t axis) const { return double(hi[axis]) - double(lo[axis]); }
  double area() const {
    if (empty()) return 0.0;
    const double x = extent(0), y = extent(1), z = extent(2);
    return 2.0 * (x * y + y * z + z * x);
  }
  double volume() const {
    if (empty()) return 0.0;
    return extent(0) * extent(1) * extent(2);
  }
  static Box overlap(const Box& a, const Box& b) {
    Box o;
    for (size_t k = 0; k < 3; ++k) {
      o.lo[k] = std::max(a.lo[k], b.lo[k]);
      o.hi[k] = std::min(a.hi[k], b.hi[k]);
    }
    return o;
  }
};

// A triangle, or the part of it inside `box` once spatial splits have cut it: a triangle
// may have several references, in different subtrees, whose boxes bound its pieces.
struct Reference {
  Box box;
  unsigned triangle;
};

// A builder's view of the references it partitions (in place, where splits add none).
struct References {
  Reference* first;
  Reference* last;
  size_t size() const { return size_t(last - first); }
  Reference* begin() const { return first; }
  Reference* end() const { return last; }
};

struct BinaryNode {
  Box box;
  int left = -1, right = -1;  // children when count == 0
  unsigned first = 0, count = 0;  // a leaf's triangles: leafTriangles[first, first + count)
};

// A binary tree and the file-order ids of its leaves' triangles, leaf after leaf depth first.
struct BinaryTree {
  std::vector<BinaryNode> nodes;
  std::vector<unsigned> leafTriangles;
};

// The references' centroids' bounds, and the object split's bins over them. In double, and
// as twice the centroid, lo + hi, which cannot overflow (float's lo + hi did past FLT_MAX /
// 2): a centroid's bin along an axis is (sum - lo) * scale, at most kBins - 1. The scale is
// finite for any two distinct centroids (1e-45 apart or 7e38), and the index a finite
// number in [0, kBins (1 + 2^-50)]: float's kBins / extent was inf over denormal extents,
// (c - lo) inf over the float range, and int(inf) or int(NaN) indexed the bins out of
// bounds. The partition uses the very same index as the binning, so a split's children hold
// exactly the references its cost counted, neither side empty.
struct CentroidBins {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double scale[3] = {};  // 0 where every centroid is the same along the axis

  static double sum(const Box& b, size_t axis) { return double(b.lo[axis]) + double(b.hi[axis]); }
  void grow(const Box& b) {
    for (size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], sum(b, a));
      hi[a] = std::max(hi[a], sum(b, a));
    }
  }
  // Once every reference has grown the bounds.
  void setScale() {
    for (size_t a = 0; a < 3; ++a) {
      const double extent = hi[a] - lo[a];
      scale[a] = extent > 0.0 ? double(kBins) / extent : 0.0;
    }
  }
  // sum - lo >= 0: lo is the least of the very same sums, and rounding is monotonic.
  int bin(const Box& b, size_t axis) const {
    return int(std::min((sum(b, axis) - lo[axis]) * scale[axis], double(kBins - 1)));
  }
};

// A reference per triangle, with the triangle's box, and the triangles' corners side by
// side (three per triangle, for clipping), on `threads` threads.
std::vector<Reference> triangleReferences(const Scene& scene, unsigned threads, std::vector<float3>& corners) {
  std::vector<Reference> refs(scene.triangleCount());
  const size_t n = refs.size();
  corners.resize(3 * n);
  auto range = [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      for (size_t k = 0; k < 3; ++k) {
        corners[3 * t + k] = scene.corner(t, int(k));
        refs[t].box.grow(corners[3 * t + k]);
      }
      refs[t].triangle = unsigned(t);
    }
  };
  std::vector<std::thread> workers;
  for (unsigned w = 1; w < threads; ++w) workers.emplace_back(range, n * w / threads, n * (w + 1) / threads);
  range(0, n / threads);
  for (auto& w : workers) w.join();
  return refs;
}

// The box of the point where the edge pq crosses the plane x[a] = position, rounded
// outwards: widened before its rounding to float by more than the error of computing it in
// T and of that rounding together. In float (edges whose coordinates are at most 2^125,
// so that nothing overflows), by 2^-20 of the edge's magnitude M along each axis and 2^-147:
// the interpolation errs by less than 12 2^-24 M + 2^-149 (denormal results round
// absolutely), the rounding by 2^-24 M + 2^-150. In double (any finite edge: in float,
// q - p overflows across the float range, and the point was then NaN), by 2^-22 M and
// 2^-149, against a few 2^-53 M and the same rounding. Branch-free (a directed rounding's
// compare and step cost a tenth of the build).
template <typename T>
void edgeCrossing(const float3& p, const float3& q, size_t a, float position, float3& lo, float3& hi) {
  constexpr bool single = sizeof(T) == sizeof(float);
  const T relative = single ? T(0x1p-20) : T(0x1p-22), absolute = single ? T(0x1p-147) : T(0x1p-149);
  const T s = (T(position) - T(p[a])) / (T(q[a]) - T(p[a]));
  for (size_t c = 0; c < 3; ++c) {
    const T x = T(p[c]) + (T(q[c]) - T(p[c])) * s,
            slack = std::max(std::fabs(T(p[c])), std::fabs(T(q[c]))) * relative + absolute;
    if constexpr (single) {
      lo[c] = x - slack;
      hi[c] = x + slack;
    } else {
      lo[c] = float(std::max(x - slack, -double(FLT_MAX)));
      hi[c] = float(std::min(x + slack, double(FLT_MAX)));
    }
  }
  lo[a] = hi[a] = position;
}

// The boxes of a reference's triangle piece on either side of the plane x[axis] = position
// (either may be empty). The crossing points of edges with the plane are widened by the
// rounding of their interpolation (edgeCrossing), so the boxes stay conservative and no ray
// slips between the two, denormal coordinates and coordinates near FLT_MAX included.
std::pair<Box, Box> splitReference(const float3* corners, const Reference& ref, int axis, float position) {
  const size_t a = size_t(axis);
  const float3* v = corners + 3 * size_t(ref.triangle);
  float magnitude = 0.f;
  for (size_t k = 0; k < 3; ++k)
    for (size_t c = 0; c < 3; ++c) magnitude = std::max(magnitude, std::fabs(v[k][c]));
  const bool inFloat = magnitude <= 0x1p125f;
  Box left, right;
  for (size_t k = 0; k < 3; ++k) {
    const float3& p = v[k];
    const float3& q = v[k == 2 ? 0 : k + 1];
    if (p[a] <= position) left.grow(p);
    if (p[a] >= position) right.grow(p);
    if ((p[a] < position && q[a] > position) || (p[a] > position && q[a] < position)) {
      float3 lo, hi;
      if (inFloat)
        edgeCrossing<float>(p, q, a, position, lo, hi);
      else
        edgeCrossing<double>(p, q, a, position, lo, hi);
      left.grow(lo, hi);
      right.grow(lo, hi);
    }
  }
  left.hi[a] = std::min(left.hi[a], position);
  right.lo[a] = std::max(right.lo[a], position);
  return {Box::overlap(left, ref.box), Box::overlap(right, ref.box)};
}

// Subtrees at least this large build their second child on a thread of its own (while the
// tree is shallower than parallelDepth): smaller ones cost less than starting a thread.
constexpr unsigned kParallelTriangles = 16384;

// A binary subtree over references, root at node 0, children depth first (left subtree,
// then right). Large right subtrees are built concurrently by builders of their own and
// grafted in at the index a serial build gives them, so the tree is the same whatever the
// thread count. A subtree may add up to `room` references by spatial splits; what a split
// leaves of it is shared by the children in proportion to their references, so the
// budget, too, does not depend on the order subtrees are built in.
class BinaryBuilder {
 public:
  BinaryBuilder(const float3* corners, double rootArea, double rootVolume, int parallelDepth)
      : corners_(corners), rootArea_(rootArea), rootVolume_(rootVolume), parallelDepth_(parallelDepth) {}

  BinaryTree build(References refs, size_t room, int depth = 0) {
    tree_.nodes.reserve(2 * refs.size());
    tree_.leafTriangles.reserve(refs.size());
    tree_.nodes.emplace_back();
    split(0, refs, room, depth);
    return std::move(tree_);
  }

 private:
  struct Split {
    int axis = -1;
    int bin = -1;  // the last bin on the left
    float position = 0.f;  // a spatial split's plane
    double cost = INFINITY;
    bool spatial = false;
    Box left, right;  // the children's boxes
    size_t leftCount = 0, rightCount = 0;
  };

  // Triangles cost by groups of four (half a TriangleBlock8), as Embree's builders count by
  // their leaves' blocks: counting single triangles favours even halves (twelve as six and
  // six, two blocks a quarter empty) where eight and four cost the same to test once
  // collapsed. Whole blocks of eight would be the leaf test's true cost, but they make the
  // builder stop at bigger, looser leaves that the wide collapse can no longer split
  // (bench/RESULTS.md: the Cornell box's tree got worse).
  static double groupedCount(size_t n) { return double((n + kCountGroup - 1) / kCountGroup * kCountGroup); }

  // Finite for any finite boxes: areas in double, the parent's area > 0 and at least the
  // children's. perArea: kTriangleCost over the parent's area (a division per plane was a
  // tenth of the object splits' time).
  static double cost(const Box& left, size_t nLeft, const Box& right, size_t nRight, double perArea) {
    return kTraversalCost + (left.area() * groupedCount(nLeft) + right.area() * groupedCount(nRight)) * perArea;
  }

  // Binned over the references' centroids, all three axes in one pass over them.
  Split objectSplit(References refs, const CentroidBins& centroids, double parentArea) const {
    Box bins[3][kBins];
    size_t counts[3][kBins] = {};
    for (const Reference& r : refs) {
      for (size_t a = 0; a < 3; ++a) {
        const int b = centroids.bin(r.box, a);
        bins[a][b].grow(r.box);
        ++counts[a][b];
      }
    }
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      if (centroids.scale[axis] == 0.0) continue;
      sweep(bins[axis], counts[axis], counts[axis], kBins, parentArea, [](int) { return 0.f; }, axis, false, best);
    }
    return best;
  }

  // Binned over the node's box: each reference is cut at the bin planes it spans, its pieces
  // grow the bins, and it enters the bin of its lowest piece and leaves by its highest.
  // The bins' planes are placed in double and rounded to floats, which lie in the box
  // (float's extent overflowed to inf, and its width underflowed to 0 over denormal
  // extents); a plane rounded onto a neighbour's or the box's face only leaves a bin empty.
  Split spatialSplit(References refs, const Box& box, double parentArea) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      const size_t a = size_t(axis);
      const double lo = box.lo[a], extent = box.extent(a);
      if (!(extent > 0.0)) continue;
      const double width = extent / kSpatialBins;
      auto plane = [&](int b) { return float(lo + double(b + 1) * width); };
      auto binOf = [&](float x) { return int(std::clamp((double(x) - lo) / width, 0.0, double(kSpatialBins - 1))); };
      Box bins[kSpatialBins];
      size_t enter[kSpatialBins] = {}, leave[kSpatialBins] = {};
      for (const Reference& r : refs) {
        const int first = binOf(r.box.lo[a]), last = std::max(first, binOf(r.box.hi[a]));
        ++enter[first];
        ++leave[last];
        Reference rest = r;
        for (int b = first; b < last; ++b) {
          const auto [piece, above] = splitReference(corners_, rest, axis, plane(b));
          bins[b].grow(piece);
          rest.box = above;
        }
        bins[last].grow(rest.box);
      }
      sweep(bins, enter, leave, kSpatialBins, parentArea, plane, axis, true, best);
    }
    return best;
  }

  // The SAH cost of each plane between bins: the left side counts the references that
  // enter its bins, the right side those that leave by its bins.
  template <typename Plane>
  void sweep(const Box* bins, const size_t* enter, const size_t* leave, int n, double parentArea, Plane plane,
             int axis, bool spatial, Split& best) const {
    Box rightBox[kMaxBins + 1];
    size_t rightCount[kMaxBins + 1] = {};
    for (int b = n - 1; b > 0; --b) {
      rightBox[size_t(b)] = rightBox[size_t(b) + 1];
      rightBox[size_t(b)].grow(bins[b]);
      rightCount[size_t(b)] = rightCount[size_t(b) + 1] + leave[b];
    }
    const double perArea = kTriangleCost / parentArea;
    Box left;
    size_t leftCount = 0;
    for (int b = 0; b < n - 1; ++b) {
      left.grow(bins[b]);
      leftCount += enter[b];
      const size_t right = rightCount[size_t(b) + 1];
      if (leftCount == 0 || right == 0) continue;
      const double c = cost(left, leftCount, rightBox[size_t(b) + 1], right, perArea);
      if (c < best.cost) best = {axis, b, plane(b), c, spatial, left, rightBox[size_t(b) + 1], leftCount, right};
    }
  }

  void makeLeaf(int node, References refs) {
    tree_.nodes[size_t(node)].first = unsigned(tree_.leafTriangles.size());
    tree_.nodes[size_t(node)].count = unsigned(refs.size());
    for (const Reference& r : refs) tree_.leafTriangles.push_back(r.triangle);
  }

  // Sends each reference to the side of the plane its box is on; one that straddles it is
  // cut in two, unless putting it whole on one side costs less (Stich et al.'s reference
  // unsplitting), which also spares the budget.
  void partitionSpatial(References refs, const Split& s, std::vector<Reference>& left,
                        std::vector<Reference>& right) const {
    const size_t a = size_t(s.axis);
    const double nl = double(s.leftCount), nr = double(s.rightCount);
    const double splitCost = s.left.area() * nl + s.right.area() * nr;
    for (const Reference& r : refs) {
      if (r.box.hi[a] <= s.position) {
        left.push_back(r);
      } else if (r.box.lo[a] >= s.position) {
        right.push_back(r);
      } else {
        Box grownLeft = s.left, grownRight = s.right;
        grownLeft.grow(r.box);
        grownRight.grow(r.box);
        const double wholeLeft = grownLeft.area() * nl + s.right.area() * (nr - 1.0);
        const double wholeRight = s.left.area() * (nl - 1.0) + grownRight.area() * nr;
        const auto [lo, hi] = splitReference(corners_, r, s.axis, s.position);
        if (lo.empty() && hi.empty()) {
          // Clipping found no piece on either side (a piece's box may be wider than its
          // piece): the reference stays whole, which is conservative.
          (wholeLeft <= wholeRight ? left : right).push_back(r);
        } else if (lo.empty()) {
          right.push_back({hi, r.triangle});
        } else if (hi.empty()) {
          left.push_back({lo, r.triangle});
        } else if (wholeLeft <= splitCost && wholeLeft <= wholeRight) {
          left.push_back(r);
        } else if (wholeRight <= splitCost) {
          right.push_back(r);
        } else {
          left.push_back({lo, r.triangle});
          right.push_back({hi, r.triangle});
        }
      }
    }
  }

  void split(int node, References refs, size_t room, int depth) {
    Box box;
    CentroidBins centroids;
    for (const Reference& r : refs) {
      box.grow(r.box);
      centroids.grow(r.box);
    }
    centroids.setScale();
    tree_.nodes[size_t(node)].box = box;
    const size_t count = refs.size();
    if (count == 1) return makeLeaf(node, refs);

    const double area = std::max(box.area(), kMinArea);
    const Split object = objectSplit(refs, centroids, area);
    Split s = object;
    if (room > 0 && s.axis >= 0 && Box::overlap(s.left, s.right).area() > kOverlapToTrySpatial * rootArea_) {
      const Split spatial = spatialSplit(refs, box, area);
      // Only within the budget: a spatial split adds at most the references it cuts.
      const size_t added = spatial.leftCount + spatial.rightCount - count;
      if (spatial.cost < s.cost * (1.0 - kSpatialSplitGain) && added <= room) s = spatial;
    }
    const unsigned mostInLeaf = box.volume() >= kRoomyVolume * rootVolume_ ? kRoomyLeaf : kMaxLeaf;
    if (s.axis >= 0 && count <= mostInLeaf && kTriangleCost * double(count) <= s.cost) return makeLeaf(node, refs);

    // A spatial split's children own their references (this frame keeps them alive);
    // an object split's partition the node's in place.
    std::vector<Reference> leftPieces, rightPieces;
    References left{refs.first, refs.first}, right{refs.last, refs.last};
    if (s.spatial) {
      leftPieces.reserve(s.leftCount);
      rightPieces.reserve(s.rightCount);
      partitionSpatial(refs, s, leftPieces, rightPieces);
      if (leftPieces.empty() || rightPieces.empty()) {
        s = object;  // unsplitting put every reference on one side: split by objects after all
      } else {
        left = {leftPieces.data(), leftPieces.data() + leftPieces.size()};
        right = {rightPieces.data(), rightPieces.data() + rightPieces.size()};
      }
    }
    if (!s.spatial && s.axis >= 0) {
      Reference* mid = std::partition(refs.first, refs.last, [&](const Reference& r) {
        return centroids.bin(r.box, size_t(s.axis)) <= s.bin;
      });
      left = {refs.first, mid};
      right = {mid, refs.last};
    }
    if (left.size() == 0 || right.size() == 0) {
      // All centroids coincide (no object split), or unsplitting sent every piece one way
      // and the object split was no split either.
      if (count <= kMaxLeaf) return makeLeaf(node, refs);
      left = {refs.first, refs.first + count / 2};
      right = {refs.first + count / 2, refs.last};
    }
    const size_t added = left.size() + right.size() - count;
    const size_t rest = room - std::min(room, added);
    const size_t leftRoom = size_t(double(rest) * double(left.size()) / double(left.size() + right.size()));
    const size_t rightRoom = rest - leftRoom;

    const int first = int(tree_.nodes.size());
    tree_.nodes.emplace_back();
    tree_.nodes.emplace_back();
    tree_.nodes[size_t(node)].left = first;
    tree_.nodes[size_t(node)].right = first + 1;
    if (depth < parallelDepth_ && right.size() >= kParallelTriangles) {
      // The two children own disjoint references: the right one on another thread.
      auto subtree = std::async(std::launch::async, [this, right, rightRoom, depth] {
        return BinaryBuilder(corners_, rootArea_, rootVolume_, parallelDepth_).build(right, rightRoom, depth + 1);
      });
      split(first, left, leftRoom, depth + 1);
      graft(first + 1, subtree.get());
    } else {
      split(first, left, leftRoom, depth + 1);
      split(first + 1, right, rightRoom, depth + 1);
    }
  }

  // Puts a subtree built on its own at `node` (its root) and after the nodes so far (its
  // other nodes, and its leaves' triangles), where a serial build numbers them.
  void graft(int node, BinaryTree subtree) {
    const int base = int(tree_.nodes.size()) - 1;  // subtree node i > 0 goes to base + i
    const unsigned leafBase = unsigned(tree_.leafTriangles.size());
    for (BinaryNode& n : subtree.nodes) {
      if (n.count == 0) {
        n.left += base;
        n.right += base;
      } else {
        n.first += leafBase;
      }
    }
    tree_.nodes[size_t(node)] = subtree.nodes[0];
    tree_.nodes.insert(tree_.nodes.end(), subtree.nodes.begin() + 1, subtree.nodes.end());
    tree_.leafTriangles.insert(tree_.leafTriangles.end(), subtree.leafTriangles.begin(), subtree.leafTriangles.end());
  }

  const float3* corners_;
  double rootArea_;
  double rootVolume_;  // INFINITY for a flat scene: no node is roomy
  int parallelDepth_;
  BinaryTree tree_;
};

// The surface area heuristic's cost of a binary tree (kTraversalCost per node visited,
// kTriangleCost per triangle tested, each weighted by its box's area over the root's): the
// build's quality, comparable between builders.
double sahCost(const std::vector<BinaryNode>& nodes) {
  const double root = std::max(nodes[0].box.area(), kMinArea);
  double cost = 0.0;
  for (const BinaryNode& n : nodes)
    cost += n.box.area() / root * (n.count == 0 ? kTraversalCost : kTriangleCost * double(n.count));
  return cost;
}

// The 8-wide tree, chosen by dynamic programming over the binary tree (Ylitie, Karras and
// Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG
// 2017). For every binary node and every number of slots i (1 to 8) it finds the cheapest
// way, by the SAH, to hang the node's subtree from at most i slots of a wide node, where a
// slot holds a wide node of its own or a leaf block, and a block may gather the triangles
// of several binary leaves (up to eight references). Opening the largest child greedily,
// as before, left many wide nodes with two or three children whose leaves their parent
// could have held, and so more levels to visit.
class WideCollapser {
 public:
  // bvhIndex[t]: file-order triangle t's index in BVH order, the id its leaves' lanes hold.
  WideCollapser(const BinaryTree& binary, const Scene& scene, const std::vector<int>& bvhIndex, Bvh& out)
      : binary_(binary.nodes), leafTriangles_(binary.leafTriangles), scene_(scene), bvhIndex_(bvhIndex), out_(out) {}

  void collapseRoot() {
    plan_.resize(binary_.size());
    planSubtrees();
    out_.stats.wideSahCost = kTraversalCost + plan_[0].cost[kWidth - 1];
    if (binary_[0].count > 0) {
      // A single-leaf tree still gets an inner root, so the root is never a leaf.
      out_.nodes.emplace_back();
      clearNode(out_.nodes[0]);
      setChild(0, 0, 0, 1);
      return;
    }
    addWideNode(0, 1);
  }

 private:
  static constexpr int kWidth = FH_BVH_WIDTH;

  // The cheapest plans for one binary node's subtree.
  struct SlotPlan {
    float cost[kWidth];  // cost[i - 1]: in at most i slots, per ray (visitWeight)
    // leftSlots[i - 1] (i >= 2, inner nodes): how many of the i slots the left child's plan
    // gets; the right child's gets the rest.
    unsigned char leftSlots[kWidth];
    bool asLeaf;  // in one slot: a leaf block, not a wide node
    unsigned references;  // in the subtree's leaves
  };

  float leafCost(float weight, unsigned references) const {
    return references <= kMaxLeaf ? weight * kLeafBlockCost : INFINITY;
  }

  // Children before parents would need the builder's numbering; an explicit post-order
  // does not.
  void planSubtrees() {
    const double rootArea = std::max(binary_[0].box.area(), kMinArea), rootVolume = binary_[0].box.volume();
    std::vector<std::pair<int, bool>> stack = {{0, false}};
    while (!stack.empty()) {
      const auto [b, childrenDone] = stack.back();
      stack.pop_back();
      const BinaryNode& n = binary_[size_t(b)];
      if (n.count == 0 && !childrenDone) {
        stack.push_back({b, true});
        stack.push_back({n.left, false});
        stack.push_back({n.right, false});
        continue;
      }
      planNode(b, visitWeight(n.box, rootArea, rootVolume));
    }
  }

  // A box's chance of being visited, relative to the root's (see kVolumeWeight): ratios of
  // a box's to its root's, at most 1 + kVolumeWeight.
  static float visitWeight(const Box& box, double rootArea, double rootVolume) {
    const double volume = rootVolume > 0.0 ? kVolumeWeight * box.volume() / rootVolume : 0.0;
    return float(box.area() / rootArea + volume);
  }

  void planNode(int b, float weight) {
    const BinaryNode& n = binary_[size_t(b)];
    SlotPlan& p = plan_[size_t(b)];
    if (n.count > 0) {
      p.references = n.count;
      std::fill(p.cost, p.cost + kWidth, leafCost(weight, n.count));
      std::fill(p.leftSlots, p.leftSlots + kWidth, 0);
      p.asLeaf = true;
      return;
    }
    const SlotPlan& l = plan_[size_t(n.left)];
    const SlotPlan& r = plan_[size_t(n.right)];
    p.references = l.references + r.references;
    p.leftSlots[0] = 0;
    for (int i = 2; i <= kWidth; ++i) {
      float best = INFINITY;
      int bestLeft = 1;
      for (int k = 1; k < i; ++k) {
        const float c = l.cost[k - 1] + r.cost[i - k - 1];
        if (c < best) {
          best = c;
          bestLeft = k;
        }
      }
      p.cost[i - 1] = best;
      p.leftSlots[i - 1] = (unsigned char)bestLeft;
    }
    const float leaf = leafCost(weight, p.references);
    const float wide = weight * kTraversalCost + p.cost[kWidth - 1];
    p.asLeaf = leaf <= wide;
    p.cost[0] = std::min(leaf, wide);
  }

  // The binary nodes that fill the slots of binary node b's plan for at most `slots`.
  void collectSlots(int b, int slots, std::vector<int>& out) const {
    const BinaryNode& n = binary_[size_t(b)];
    if (slots == 1 || n.count > 0) {
      out.push_back(b);
      return;
    }
    const int left = plan_[size_t(b)].leftSlots[slots - 1];
    collectSlots(n.left, left, out);
    collectSlots(n.right, slots - left, out);
  }

  static void clearNode(gpu::Bvh8Node& n) { std::memset(&n, 0, sizeof n); }

  // The file-order triangles of binary node b's leaves, each once (spatial splits may have
  // put pieces of one triangle in two of them).
  void gatherTriangles(int b, std::vector<unsigned>& out) const {
    const BinaryNode& n = binary_[size_t(b)];
    if (n.count == 0) {
      gatherTriangles(n.left, out);
      gatherTriangles(n.right, out);
      return;
    }
    for (unsigned k = n.first; k < n.first + n.count; ++k)
      if (std::find(out.begin(), out.end(), leafTriangles_[k]) == out.end()) out.push_back(leafTriangles_[k]);
  }

  // The triangles (at most eight), as one SoA block.
  int addBlock(const std::vector<unsigned>& triangles) {
    gpu::TriangleBlock8 block;
    std::memset(&block, 0, sizeof block);
    for (unsigned lane = 0; lane < 8; ++lane) {
      if (lane >= triangles.size()) {
        block.id[lane] = -1;
        continue;
      }
      const unsigned triangle = triangles[lane];
      block.id[lane] = bvhIndex_[triangle];
      for (int k = 0; k < 3; ++k) {
        const float3 p = scene_.corner(triangle, k);
        for (int axis = 0; axis < 3; ++axis) block.v[k][axis][lane] = p[size_t(axis)];
      }
    }
    out_.blocks.push_back(block);
    ++out_.stats.leaves;
    return int(out_.blocks.size() - 1);
  }

  // Slot `slot` of wide node `wide` gets binary node `b`'s one-slot plan, at `depth`.
  void setChild(int wide, int slot, int b, int depth) {
    const BinaryNode& child = binary_[size_t(b)];
    int ref;
    if (plan_[size_t(b)].asLeaf) {
      std::vector<unsigned> triangles;
      gatherTriangles(b, triangles);
      ref = ~addBlock(triangles);
      out_.stats.depth = std::max(out_.stats.depth, depth);
    } else {
      ref = addWideNode(b, depth + 1);
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

  // A wide node for inner binary node b, its slots filled by b's children's plans.
  int addWideNode(int b, int depth) {
    const BinaryNode& n = binary_[size_t(b)];
    std::vector<int> children;
    const int left = plan_[size_t(b)].leftSlots[kWidth - 1];
    collectSlots(n.left, left, children);
    collectSlots(n.right, kWidth - left, children);
    const int wide = int(out_.nodes.size());
    out_.nodes.emplace_back();
    clearNode(out_.nodes.back());
    for (size_t i = 0; i < children.size(); ++i) setChild(wide, int(i), children[i], depth);
    return wide;
  }

  const std::vector<BinaryNode>& binary_;
  const std::vector<unsigned>& leafTriangles_;
  const Scene& scene_;
  const std::vector<int>& bvhIndex_;
  Bvh& out_;
  std::vector<SlotPlan> plan_;
};

// BVH order: triangles by their first reference in the leaves, depth first, so a leaf's
// triangles mostly sit together in the per-triangle arrays. `order` lists them, bvhIndex
// inverts it.
void orderTriangles(const BinaryTree& tree, size_t triangles, Bvh& bvh, std::vector<int>& bvhIndex) {
  bvhIndex.assign(triangles, -1);
  bvh.order.reserve(triangles);
  for (unsigned t : tree.leafTriangles)
    if (bvhIndex[t] < 0) {
      bvhIndex[t] = int(bvh.order.size());
      bvh.order.push_back(t);
    }
}

}  // namespace

Bvh buildBvh(const Scene& scene, BvhOptions options) {
  const auto start = std::chrono::steady_clock::now();
  // FREDHOLM_BVH_THREADS caps the default thread count, FREDHOLM_BVH_SPLITS sets the spatial
  // split budget (bench/RESULTS.md compares both).
  unsigned threads = options.threads;
  const char* cap = std::getenv("FREDHOLM_BVH_THREADS");
  if (threads == 0 && cap && *cap) threads = unsigned(std::max(1, std::atoi(cap)));
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  const char* budget = std::getenv("FREDHOLM_BVH_SPLITS");
  if (budget && *budget) options.spatialSplitBudget = std::max(0.f, std::strtof(budget, nullptr));

  Bvh bvh;
  std::vector<float3> corners;
  // The loader rejects these scenes; one built otherwise gets the same word.
  if (scene.triangleCount() == 0) throw Error("BVH: the scene has no triangles");
  std::vector<Reference> refs = triangleReferences(scene, threads, corners);
  for (size_t k = 0; k < corners.size(); ++k)
    if (!isFinite(corners[k]))
      throw Error("BVH: triangle " + std::to_string(k / 3) + " has a non-finite vertex coordinate");
  Box sceneBox;
  for (const Reference& r : refs) sceneBox.grow(r.box);
  // Levels that fork: enough subtrees for every thread, and some over for uneven splits.
  int parallelDepth = 0;
  while (threads > 1 && (1u << parallelDepth) < 4 * threads) ++parallelDepth;
  const size_t room = size_t(double(options.spatialSplitBudget) * double(refs.size()));
  const double sceneVolume = sceneBox.volume() > 0.0 ? sceneBox.volume() : INFINITY;
  BinaryBuilder builder(corners.data(), std::max(sceneBox.area(), kMinArea), sceneVolume, parallelDepth);
  const BinaryTree binary = builder.build({refs.data(), refs.data() + refs.size()}, room);
  bvh.stats.binaryNodes = binary.nodes.size();
  bvh.stats.references = binary.leafTriangles.size();
  bvh.stats.sahCost = sahCost(binary.nodes);

  std::vector<int> bvhIndex;
  orderTriangles(binary, scene.triangleCount(), bvh, bvhIndex);
  WideCollapser(binary, scene, bvhIndex, bvh).collapseRoot();
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
