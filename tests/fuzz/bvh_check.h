// What any BVH buildBvh returns must satisfy, whatever finite scene it was given: shared by
// the property test (tests/test_bvh_build.cpp) and the fuzz target (fuzz_bvh_build.cpp).
//  - checkBvh: the structure. BVH order is a permutation of the triangles, and the
//    per-triangle arrays and leaf blocks hold their vertices; the wide nodes form a tree from
//    the root that reaches every node and every block once; every used slot's box is a
//    finite box inside its parent slot's; every triangle is in a leaf, and without spatial
//    splits in exactly one, whose box and every ancestor's holds the whole triangle (with
//    them, in leaves whose boxes together cover it, checked at its corners, points inside
//    it, and where its edges cross the boxes' faces); the reported depth (the traversal
//    stack's size) is the tree's, and the SAH costs are finite.
//  - closestByTree / closestByBruteForce: one ray's closest hit found through the tree and
//    over every triangle, by the same double-precision test, so they agree exactly unless
//    the tree loses a triangle. The tree's box test is conservative: boxes are widened by
//    1e-9 of the magnitudes involved, far more than the rounding of either test (see
//    rayTriangle). That resolution is coarse beside triangles far smaller than the scene;
//    checkBvh's exact containment holds at every scale.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "scene/scene.h"

namespace fh::bvhcheck {

using Box6 = std::array<float, 6>;  // lo x, y, z, hi x, y, z

inline Box6 slotBox(const gpu::Bvh8Node& n, int i) {
  return {n.lo_x[i], n.lo_y[i], n.lo_z[i], n.hi_x[i], n.hi_y[i], n.hi_z[i]};
}

inline bool contains(const Box6& outer, const Box6& inner) {
  for (int k = 0; k < 3; ++k)
    if (!(outer[k] <= inner[k] && inner[k + 3] <= outer[k + 3])) return false;
  return true;
}

inline Box6 triangleBox(const Scene& scene, size_t t) {
  Box6 b = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
  for (int c = 0; c < 3; ++c) {
    const Vec3f p = scene.corner(t, c);
    for (int k = 0; k < 3; ++k) {
      b[k] = std::min(b[k], p[k]);
      b[k + 3] = std::max(b[k + 3], p[k]);
    }
  }
  return b;
}

inline bool meets(const Box6& a, const Box6& b) {
  for (int k = 0; k < 3; ++k)
    if (a[k] > b[k + 3] || b[k] > a[k + 3]) return false;
  return true;
}

// Whether x lies in one of the boxes, each widened by tol.
inline bool inSomeBox(const std::vector<Box6>& boxes, const double x[3], double tol) {
  for (const Box6& b : boxes) {
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && x[k] >= double(b[k]) - tol && x[k] <= double(b[k + 3]) + tol;
    if (in) return true;
  }
  return false;
}

// A point of triangle t outside every box, if there is one ("" if none was found): its
// corners, points inside it, and the points where its edges cross the planes of the boxes'
// faces, where the clipping of spatial splits rounds (a gap there lets rays through). The
// points are computed in double, within 1e-14 of the triangle's magnitude of the true ones.
inline std::string uncoveredPoint(const Scene& scene, size_t t, const std::vector<Box6>& boxes) {
  double v[3][3], magnitude = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) {
      v[c][k] = scene.corner(t, c)[size_t(k)];
      magnitude = std::max(magnitude, std::fabs(v[c][k]));
    }
  const double tol = 1e-14 * magnitude;
  auto outside = [&](const double x[3]) {
    if (inSomeBox(boxes, x, tol)) return std::string();
    std::ostringstream s;
    s.precision(17);
    s << "(" << x[0] << " " << x[1] << " " << x[2] << ")";
    return s.str();
  };
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; i + j <= 4; ++j) {
      const double b1 = i / 4.0, b2 = j / 4.0, b0 = 1.0 - b1 - b2;
      double x[3];
      for (int k = 0; k < 3; ++k) x[k] = b0 * v[0][k] + b1 * v[1][k] + b2 * v[2][k];
      if (i + j == 0 || i == 4 || j == 4) std::memcpy(x, v[i == 4 ? 1 : j == 4 ? 2 : 0], sizeof x);  // corners exactly
      const std::string out = outside(x);
      if (!out.empty()) return out;
    }
  for (const Box6& b : boxes)
    for (int a = 0; a < 3; ++a)
      for (double plane : {double(b[a]), double(b[a + 3])})
        for (int e = 0; e < 3; ++e) {
          const double* p = v[e];
          const double* q = v[(e + 1) % 3];
          if (!((p[a] < plane && plane < q[a]) || (q[a] < plane && plane < p[a]))) continue;
          const double s = (plane - p[a]) / (q[a] - p[a]);
          double x[3];
          for (int k = 0; k < 3; ++k) x[k] = p[k] + (q[k] - p[k]) * s;
          x[a] = plane;
          const std::string out = outside(x);
          if (!out.empty()) return out;
        }
  return "";
}

inline std::string describe(const Box6& b) {
  std::ostringstream s;
  s.precision(9);
  s << "[" << b[0] << " " << b[1] << " " << b[2] << " .. " << b[3] << " " << b[4] << " " << b[5] << "]";
  return s.str();
}

// "" if the BVH of `scene` holds every invariant, else the first violation found.
// wholeTriangles: built without spatial splits (BvhOptions::spatialSplitBudget 0).
inline std::string checkBvh(const Scene& scene, const Bvh& bvh, bool wholeTriangles) {
  std::ostringstream why;
  const size_t n = scene.triangleCount();
  if (bvh.order.size() != n) return "order holds " + std::to_string(bvh.order.size()) + " of " + std::to_string(n);
  std::vector<int> bvhIndex(n, -1);
  for (size_t k = 0; k < n; ++k) {
    const unsigned t = bvh.order[k];
    if (t >= n || bvhIndex[t] >= 0) return "order is not a permutation (at " + std::to_string(k) + ")";
    bvhIndex[t] = int(k);
  }
  if (bvh.triangles.size() != 12 * n) return "triangles holds " + std::to_string(bvh.triangles.size()) + " floats";
  for (size_t k = 0; k < n; ++k) {
    const float* f = &bvh.triangles[12 * k];
    unsigned id;
    std::memcpy(&id, &f[3], 4);
    if (id != bvh.order[k]) return "triangles[" + std::to_string(k) + "] names the wrong triangle";
    for (int c = 0; c < 3; ++c) {
      const Vec3f p = scene.corner(bvh.order[k], c);
      if (f[4 * c] != p[0] || f[4 * c + 1] != p[1] || f[4 * c + 2] != p[2])
        return "triangles[" + std::to_string(k) + "] corner " + std::to_string(c) + " differs from the scene's";
    }
  }
  if (bvh.nodes.empty()) return "no root node";
  if (!std::isfinite(bvh.stats.sahCost) || !std::isfinite(bvh.stats.wideSahCost))
    return "SAH cost not finite: " + std::to_string(bvh.stats.sahCost) + ", " + std::to_string(bvh.stats.wideSahCost);

  std::vector<int> nodeSeen(bvh.nodes.size(), 0), blockSeen(bvh.blocks.size(), 0), leavesOf(n, 0);
  std::vector<std::vector<Box6>> leafBoxes(wholeTriangles ? 0 : n);  // the boxes of each triangle's leaves
  struct Pending {
    int node, depth;
    bool hasBox;
    Box6 box;  // the slot box this node hangs from (not for the root)
  };
  std::vector<Pending> stack = {{0, 1, false, {}}};
  nodeSeen[0] = 1;
  int deepest = 0;
  while (!stack.empty()) {
    const Pending at = stack.back();
    stack.pop_back();
    const gpu::Bvh8Node& node = bvh.nodes[size_t(at.node)];
    int used = 0;
    for (int i = 0; i < 8; ++i) {
      const int child = node.child[i];
      if (child == 0) continue;
      ++used;
      const Box6 box = slotBox(node, i);
      why << "node " << at.node << " slot " << i << " " << describe(box) << ": ";
      for (float v : box)
        if (!std::isfinite(v)) return why.str() + "a non-finite bound";
      for (int k = 0; k < 3; ++k)
        if (!(box[k] <= box[k + 3])) return why.str() + "an empty box";
      if (at.hasBox && !contains(at.box, box)) return why.str() + "not inside its parent's slot " + describe(at.box);
      if (child > 0) {
        if (size_t(child) >= bvh.nodes.size()) return why.str() + "child node out of range";
        if (nodeSeen[size_t(child)]++) return why.str() + "node " + std::to_string(child) + " reached twice";
        stack.push_back({child, at.depth + 1, true, box});
      } else {
        const size_t b = size_t(~child);
        if (b >= bvh.blocks.size()) return why.str() + "leaf block out of range";
        if (blockSeen[b]++) return why.str() + "block " + std::to_string(b) + " reached twice";
        deepest = std::max(deepest, at.depth);
        const gpu::TriangleBlock8& block = bvh.blocks[b];
        int lanes = 0;
        for (int lane = 0; lane < 8; ++lane) {
          const int id = block.id[lane];
          if (id < 0) continue;
          ++lanes;
          if (size_t(id) >= n) return why.str() + "lane id out of range";
          for (int other = 0; other < lane; ++other)
            if (block.id[other] == id) return why.str() + "a triangle twice in one block";
          const size_t t = bvh.order[size_t(id)];
          ++leavesOf[t];
          if (!wholeTriangles) leafBoxes[t].push_back(box);
          for (int c = 0; c < 3; ++c) {
            const Vec3f p = scene.corner(t, c);
            for (int k = 0; k < 3; ++k)
              if (block.v[c][k][lane] != p[size_t(k)]) return why.str() + "a block lane's vertex differs from the scene's";
          }
          const Box6 tb = triangleBox(scene, t);
          if (wholeTriangles ? !contains(box, tb) : !meets(box, tb))
            return why.str() + "triangle " + std::to_string(t) + " " + describe(tb) +
                   (wholeTriangles ? " not inside its leaf" : " does not meet its leaf");
        }
        if (lanes == 0) return why.str() + "an empty leaf block";
      }
      why.str("");
    }
    if (used == 0) return "node " + std::to_string(at.node) + " has no children";
  }
  for (size_t k = 0; k < nodeSeen.size(); ++k)
    if (!nodeSeen[k]) return "node " + std::to_string(k) + " unreachable";
  for (size_t k = 0; k < blockSeen.size(); ++k)
    if (!blockSeen[k]) return "block " + std::to_string(k) + " unreachable";
  for (size_t t = 0; t < n; ++t) {
    if (leavesOf[t] == 0) return "triangle " + std::to_string(t) + " in no leaf";
    if (wholeTriangles && leavesOf[t] != 1)
      return "triangle " + std::to_string(t) + " in " + std::to_string(leavesOf[t]) + " leaves without spatial splits";
    if (!wholeTriangles) {
      const std::string gap = uncoveredPoint(scene, t, leafBoxes[t]);
      if (!gap.empty())
        return "triangle " + std::to_string(t) + ": its point " + gap + " is in none of its " +
               std::to_string(leafBoxes[t].size()) + " leaves' boxes";
    }
  }
  if (deepest != bvh.stats.depth)
    return "stats.depth " + std::to_string(bvh.stats.depth) + ", the tree's " + std::to_string(deepest);
  if (bvh.stats.wideNodes != bvh.nodes.size() || bvh.stats.leaves != bvh.blocks.size()) return "stats miscount";
  return "";
}

// A ray's closest hit: t and the file-order triangle, the lower index among equal t.
struct Hit {
  double t = INFINITY;
  long triangle = -1;
  bool operator==(const Hit& o) const { return t == o.t && triangle == o.triangle; }
  bool operator!=(const Hit& o) const { return !(*this == o); }
};

// The tree is traversed with every box widened by `pad`: 1e-9 of the largest magnitude
// among the scene's coordinates and the ray's origin, M.
inline double padFor(const Scene& scene, const double org[3]) {
  double m = 0.0;
  for (float x : scene.positions) m = std::max(m, std::fabs(double(x)));
  for (int k = 0; k < 3; ++k) m = std::max(m, std::fabs(org[k]));
  return 1e-9 * m + 1e-300;
}

inline double norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Moller-Trumbore in double (no overflow or underflow for float triangles and rays): the
// hit distance along dir (not normalised), or INFINITY. Only well-conditioned hits count,
// where |det| is at least 1e-4 of |e1| |dir| |e2| (the triangle no sliver, the ray not
// grazing it): there the test misplaces the hit point by at most about 5 2^-53 |org - v0| /
// 1e-4 + 5 2^-53 |e1| / 1e-4, about 2e-11 M, far within pad, so the true ray passes within
// pad of a point of the triangle, which
// is in a leaf's box (the piece's, where spatial splits cut it): the widened traversal must
// reach it. Ill-conditioned hits, which double rounding may invent anywhere (a sliver
// 5e36 long and 1e-17 wide reported hit 1.7e32 from its box), count in neither.
inline double rayTriangle(const Scene& scene, size_t t, const double org[3], const double dir[3]) {
  double v[3][3];
  for (int c = 0; c < 3; ++c) {
    const Vec3f p = scene.corner(t, c);
    for (int k = 0; k < 3; ++k) v[c][k] = p[size_t(k)];
  }
  const double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
  const double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
  const double p[3] = {dir[1] * e2[2] - dir[2] * e2[1], dir[2] * e2[0] - dir[0] * e2[2], dir[0] * e2[1] - dir[1] * e2[0]};
  const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
  if (!(std::fabs(det) >= 1e-4 * norm(e1) * norm(dir) * norm(e2)) || det == 0.0 || !std::isfinite(det)) return INFINITY;
  const double s[3] = {org[0] - v[0][0], org[1] - v[0][1], org[2] - v[0][2]};
  const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
  if (!(u >= 0.0 && u <= 1.0)) return INFINITY;
  const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  const double w = (dir[0] * q[0] + dir[1] * q[1] + dir[2] * q[2]) / det;
  if (!(w >= 0.0 && u + w <= 1.0)) return INFINITY;
  const double d = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
  return d >= 0.0 && std::isfinite(d) ? d : INFINITY;
}

inline void consider(const Scene& scene, size_t t, const double org[3], const double dir[3], Hit& best) {
  const double d = rayTriangle(scene, t, org, dir);
  if (d < best.t || (d == best.t && d < INFINITY && long(t) < best.triangle)) best = {d, long(t)};
}

inline Hit closestByBruteForce(const Scene& scene, const double org[3], const double dir[3]) {
  Hit best;
  for (size_t t = 0; t < scene.triangleCount(); ++t) consider(scene, t, org, dir, best);
  return best;
}

// Whether the ray meets the box widened by pad anywhere ahead of its origin. The slab
// distances' rounding (1e-16 of M over the direction) is far inside the widening.
inline bool rayMeetsBox(const Box6& box, const double org[3], const double dir[3], double pad) {
  double near = 0.0, far = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const double lo = double(box[k]) - pad, hi = double(box[k + 3]) + pad;
    if (dir[k] == 0.0) {
      if (org[k] < lo || org[k] > hi) return false;
      continue;
    }
    double t0 = (lo - org[k]) / dir[k], t1 = (hi - org[k]) / dir[k];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
  }
  return near <= far;
}

// Every slot the ray meets is visited (no culling by the current hit), so the answer
// depends on the boxes alone. For a tree that checkBvh passed.
inline Hit closestByTree(const Scene& scene, const Bvh& bvh, const double org[3], const double dir[3]) {
  const double pad = padFor(scene, org);
  Hit best;
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const gpu::Bvh8Node& node = bvh.nodes[size_t(stack.back())];
    stack.pop_back();
    for (int i = 0; i < 8; ++i) {
      const int child = node.child[i];
      if (child == 0 || !rayMeetsBox(slotBox(node, i), org, dir, pad)) continue;
      if (child > 0) {
        stack.push_back(child);
        continue;
      }
      const gpu::TriangleBlock8& block = bvh.blocks[size_t(~child)];
      for (int lane = 0; lane < 8; ++lane)
        if (block.id[lane] >= 0) consider(scene, bvh.order[size_t(block.id[lane])], org, dir, best);
    }
  }
  return best;
}

}  // namespace fh::bvhcheck
