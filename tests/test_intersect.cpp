// The intersect kernels against a brute-force double-precision reference on the same
// rays, for every corpus scene and ray kind; watertightness on shared edges and vertices
// of closed meshes; and no self-intersection of spawned rays at any scene scale.
//
// The oracle: triangles grown and shrunk by the error a float test may make in the ray's
// distance to an edge (2^-18 of the magnitudes involved, see floatEdgeMargin) bracket
// every answer a correct kernel may give. A closest hit must be a triangle of the grown
// set at the reference distance (within 1e-5 of the magnitudes, divided by the cosine
// to the plane), with nothing of the shrunk set closer; a miss must miss the shrunk set.
// So hits and misses agree except within that margin of an edge, t agrees tightly, and
// the triangle agrees unless two are tied.
#include <array>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <random>
#include <set>

#include "accel/bvh.h"
#include "base/vec.h"
#include "bench/ray_workload.h"
#include "device/kernel_sources.h"
#include "device/program.h"
#include "scene/icosphere.h"
#include "scene/scene_loader.h"
#include "scene_builder.h"
#include "test_support.h"

namespace fh {
namespace {

struct Rays {
  std::vector<float> org, dir;  // float4 each
  void add(const float3& o, const float3& d, float tMin = 0.f, float tMax = INFINITY) {
    org.insert(org.end(), {o[0], o[1], o[2], tMin});
    dir.insert(dir.end(), {d[0], d[1], d[2], tMax});
  }
  size_t size() const { return org.size() / 4; }
};

double magnitude(const float* o4) { return std::max({std::fabs(o4[0]), std::fabs(o4[1]), std::fabs(o4[2])}); }

// Allowed |t_device - t_reference| for a ray from `org` hitting `triangle`: the float
// error of the point, divided by the cosine to the plane (t of a grazing ray is
// ill-conditioned: a small error across the plane is a long way along the ray).
double tTolerance(const Scene& scene, size_t triangle, const float* org, const float* dir, double t) {
  const float3 n = cross(scene.corner(triangle, 1) - scene.corner(triangle, 0),
                         scene.corner(triangle, 2) - scene.corner(triangle, 0));
  const float3 d{dir[0], dir[1], dir[2]};
  const double cosine = length(n) > 0.f ? std::fabs(dot(normalize(n), normalize(d))) : 1.0;
  return 1e-5 * (magnitude(org) + t) / std::max(cosine, 1e-4) + 1e-30;
}

// Distance between the point the device's barycentrics name on `triangle` and the
// reference hit point org + tRef * dir, in double.
double hitPointError(const Scene& scene, size_t triangle, float b1, float b2, const double org[3],
                     const double dir[3], double tRef) {
  double err = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double v0 = scene.corner(triangle, 0)[axis], v1 = scene.corner(triangle, 1)[axis],
                 v2 = scene.corner(triangle, 2)[axis];
    const double onTriangle = v0 * (1.0 - double(b1) - double(b2)) + v1 * double(b1) + v2 * double(b2);
    const double onRay = org[axis] + tRef * dir[axis];
    const double e = std::fabs(onTriangle - onRay);
    if (!(e <= err)) err = e;  // NaN stays NaN (std::max would drop it)
  }
  return err;
}

struct Mismatch {
  size_t ray;
  std::string what;
};

// Checks closest hits (BVH-order triangle ids mapped to file order) and any-hit answers.
std::vector<Mismatch> checkRays(const Scene& scene, const Bvh& bvh, const Rays& rays, const std::vector<float>& hits,
                                const std::vector<int>& occluded, size_t first, size_t last) {
  std::vector<Mismatch> bad;
  for (size_t i = first; i < last; ++i) {
    const float* o = &rays.org[4 * i];
    const float* d = &rays.dir[4 * i];
    const double org[3] = {o[0], o[1], o[2]}, dir[3] = {d[0], d[1], d[2]};
    const test::BruteHits ref = test::bruteForceBands(scene, org, dir, o[3], d[3]);
    const float t = hits[4 * i];
    int bvhTri;
    std::memcpy(&bvhTri, &hits[4 * i + 3], 4);
    std::ostringstream why;
    if (bvhTri < 0) {
      if (ref.shrunk.triangle >= 0) why << "device missed; reference hits triangle " << ref.shrunk.triangle << " at t=" << ref.shrunk.t;
    } else {
      const size_t tri = bvh.order[size_t(bvhTri)];
      const double tRef = test::rayTriangleWithMargin(scene, tri, org, dir, test::floatEdgeMargin(scene, tri, org));
      const double tol = tTolerance(scene, tri, o, d, tRef);
      const double pointError = hitPointError(scene, tri, hits[4 * i + 1], hits[4 * i + 2], org, dir, tRef);
      if (!(std::fabs(t - tRef) <= tol))
        why << "device hit triangle " << tri << " at t=" << t << ", reference t for it " << tRef;
      else if (!(pointError <= tol * length(float3{d[0], d[1], d[2]})))
        why << "device barycentrics (" << hits[4 * i + 1] << ", " << hits[4 * i + 2] << ") on triangle " << tri
            << " name a point " << pointError << " from the reference hit";
      else if (ref.shrunk.t < t - tol)
        why << "device hit triangle " << tri << " at t=" << t << " but triangle " << ref.shrunk.triangle
            << " is closer at " << ref.shrunk.t;
    }
    const bool mustBeOccluded = ref.shrunk.triangle >= 0, mayBeOccluded = ref.grown.triangle >= 0;
    if (occluded[i] && !mayBeOccluded) why << " any-hit says occluded, reference sees nothing";
    if (!occluded[i] && mustBeOccluded) why << " any-hit says free, reference hits " << ref.shrunk.triangle;
    if (!why.str().empty()) {
      why << " [org " << o[0] << " " << o[1] << " " << o[2] << " dir " << d[0] << " " << d[1] << " " << d[2] << "]";
      bad.push_back({i, why.str()});
    }
  }
  return bad;
}

class RayCasting {
 public:
  explicit RayCasting(const Scene& s) : scene(s), bvh(buildBvh(s)), caster(dc, bvh), work(dc, s, bvh, caster) {}

  // Traces `rays` with both kernels and checks every ray against the reference on two threads.
  void expectMatchesReference(const Rays& rays, const std::string& kind) {
    RayQueue q = work.upload(rays.org, rays.dir);
    const cl::Buffer hitBuffer = work.closestHits(q, RayOrder::OneByOne);
    cl::Buffer occludedBuffer =
        allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, q.count * 4ull + 4, "occluded");
    caster.intersectAny(q.org, q.dir, occludedBuffer, q.count, RayOrder::OneByOne);
    const std::vector<float> hits = work.readFloat4(hitBuffer, q.count);
    std::vector<int> occluded(q.count);
    FH_CL(dc.queue.enqueueReadBuffer(occludedBuffer, CL_TRUE, 0, q.count * 4ull, occluded.data()));

    expectPacketsMatchSingleRays(rays, hits, occluded, kind);
    expectBatchesMatchSingleRays(rays, hits, occluded, kind);

    const size_t half = rays.size() / 2;
    auto second = std::async(std::launch::async, checkRays, std::cref(scene), std::cref(bvh), std::cref(rays),
                             std::cref(hits), std::cref(occluded), half, rays.size());
    std::vector<Mismatch> bad = checkRays(scene, bvh, rays, hits, occluded, 0, half);
    for (auto& m : second.get()) bad.push_back(m);
    size_t hitsSeen = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      int tri;
      std::memcpy(&tri, &hits[4 * i + 3], 4);
      hitsSeen += tri >= 0;
    }
    EXPECT_TRUE(bad.empty()) << kind << ": " << bad.size() << " of " << rays.size() << " rays disagree; first: ray "
                             << (bad.empty() ? 0 : bad[0].ray) << ": " << (bad.empty() ? "" : bad[0].what);
    lastHitFraction = double(hitsSeen) / double(std::max<size_t>(1, rays.size()));
  }

  // The packet kernels trace the same rays eight at a time: every hit, its t and
  // barycentrics, and every any-hit answer must be the single rays' bit for bit. A packet
  // whose rays share the watertight test's axis order loads each triangle's components once
  // for all; otherwise each lane picks its own. So rays are traced twice: in the batch's
  // order (incoherent kinds mix axis orders in most packets), and sorted by that order
  // (every packet shares one).
  void expectPacketsMatchSingleRays(const Rays& rays, const std::vector<float>& hits,
                                    const std::vector<int>& occluded, const std::string& kind) {
    std::vector<size_t> order(rays.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    expectPacketsMatchSingleRays(rays, order, hits, occluded, kind + ", packets in the batch's order");
    auto axisOrder = [&](size_t i) {
      const float* d = &rays.dir[4 * i];
      const float a[3] = {std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])};
      const int kz = a[0] > a[1] ? (a[0] > a[2] ? 0 : 2) : (a[1] > a[2] ? 1 : 2);
      return 2 * kz + (d[kz] < 0.f);
    };
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return axisOrder(a) < axisOrder(b); });
    expectPacketsMatchSingleRays(rays, order, hits, occluded, kind + ", packets sorted by axis order");
  }

  void expectPacketsMatchSingleRays(const Rays& rays, const std::vector<size_t>& order,
                                    const std::vector<float>& hits, const std::vector<int>& occluded,
                                    const std::string& kind) {
    Rays sorted;
    for (size_t i : order) {
      sorted.org.insert(sorted.org.end(), &rays.org[4 * i], &rays.org[4 * i + 4]);
      sorted.dir.insert(sorted.dir.end(), &rays.dir[4 * i], &rays.dir[4 * i + 4]);
    }
    RayQueue q = work.upload(sorted.org, sorted.dir);
    cl::Buffer packetHits = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, q.count * 16ull + 16, "hits");
    cl::Buffer packetOccluded =
        allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, q.count * 4ull + 4, "occluded");
    caster.intersectClosest(q.org, q.dir, packetHits, q.count, RayOrder::Coherent);
    caster.intersectAny(q.org, q.dir, packetOccluded, q.count, RayOrder::Coherent);
    const std::vector<float> ph = work.readFloat4(packetHits, q.count);
    std::vector<int> po(q.count);
    FH_CL(dc.queue.enqueueReadBuffer(packetOccluded, CL_TRUE, 0, q.count * 4ull, po.data()));
    size_t differ = 0, first = 0;
    for (size_t k = 0; k < q.count; ++k) {
      const size_t i = order[k];
      if (std::memcmp(&ph[4 * k], &hits[4 * i], 16) != 0 || po[k] != occluded[i]) first = differ++ ? first : k;
    }
    EXPECT_EQ(differ, 0u) << kind << ": packets differ from single rays on " << differ << " of " << q.count
                          << " rays; first: ray " << order[first] << ", t " << hits[4 * order[first]] << " vs "
                          << ph[4 * first] << ", occluded " << occluded[order[first]] << " vs " << po[first];
  }

  // The CPU's kernels for incoherent batches, closest hits eight rays to a work-item and
  // any-hit streams FH_STREAM rays to a work-item, must give every ray the single rays'
  // answer, bit for bit: in the batch's order, and shuffled, so that each stream's rays part
  // ways at the root, and a batch that ends in part-filled work-items.
  void expectBatchesMatchSingleRays(const Rays& rays, const std::vector<float>& hits, const std::vector<int>& occluded,
                                    const std::string& kind) {
    std::vector<size_t> order(rays.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    expectBatchesMatchSingleRays(rays, order, hits, occluded, kind + ", batch order");
    std::shuffle(order.begin(), order.end(), std::mt19937(11));
    order.resize(order.size() - std::min<size_t>(order.size() / 2, FH_STREAM / 2 + 1));
    expectBatchesMatchSingleRays(rays, order, hits, occluded, kind + ", shuffled");
  }

  void expectBatchesMatchSingleRays(const Rays& rays, const std::vector<size_t>& order, const std::vector<float>& hits,
                                    const std::vector<int>& occluded, const std::string& kind) {
    Rays sorted;
    for (size_t i : order) {
      sorted.org.insert(sorted.org.end(), &rays.org[4 * i], &rays.org[4 * i + 4]);
      sorted.dir.insert(sorted.dir.end(), &rays.dir[4 * i], &rays.dir[4 * i + 4]);
    }
    RayQueue q = work.upload(sorted.org, sorted.dir);
    cl::Buffer streamOccluded =
        allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, q.count * 4ull + 4, "occluded");
    caster.intersectAny(q.org, q.dir, streamOccluded, q.count, RayOrder::Incoherent);
    std::vector<int> so(q.count);
    FH_CL(dc.queue.enqueueReadBuffer(streamOccluded, CL_TRUE, 0, q.count * 4ull, so.data()));
    const std::vector<float> lh = work.readFloat4(work.closestHits(q, RayOrder::Incoherent), q.count);
    size_t streamsDiffer = 0, firstStream = 0, lanesDiffer = 0, firstLane = 0;
    for (size_t k = 0; k < q.count; ++k) {
      if (so[k] != occluded[order[k]]) firstStream = streamsDiffer++ ? firstStream : k;
      if (std::memcmp(&lh[4 * k], &hits[4 * order[k]], 16) != 0) firstLane = lanesDiffer++ ? firstLane : k;
    }
    EXPECT_EQ(streamsDiffer, 0u) << kind << ": streams differ from single rays on " << streamsDiffer << " of "
                                 << q.count << " rays; first: ray " << order[firstStream] << ", occluded "
                                 << occluded[order[firstStream]] << " vs " << so[firstStream];
    EXPECT_EQ(lanesDiffer, 0u) << kind << ": closest hits eight to a work-item differ from single rays on "
                               << lanesDiffer << " of " << q.count << " rays; first: ray " << order[firstLane]
                               << ", t " << hits[4 * order[firstLane]] << " vs " << lh[4 * firstLane];
  }

  Rays download(const RayQueue& q) {
    Rays r;
    r.org = work.readFloat4(q.org, q.count);
    r.dir = work.readFloat4(q.dir, q.count);
    return r;
  }

  const Scene& scene;
  Bvh bvh;
  DeviceContext dc{selectDevices(listDevices(), "").front()};
  RayCaster caster;
  RayWorkload work;
  double lastHitFraction = 0.0;
};

float3 randomDirection(std::mt19937& rng) {
  std::normal_distribution<float> n;
  return normalize(float3{n(rng), n(rng), n(rng)});
}

float3 pointOnTriangle(const Scene& s, size_t t, float b1, float b2) {
  return s.corner(t, 0) * (1.f - b1 - b2) + s.corner(t, 1) * b1 + s.corner(t, 2) * b2;
}

struct SceneBox {
  float3 lo, hi;
  float3 random(std::mt19937& rng) const {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    return {lo[0] + u(rng) * (hi[0] - lo[0]), lo[1] + u(rng) * (hi[1] - lo[1]), lo[2] + u(rng) * (hi[2] - lo[2])};
  }
};

SceneBox expandedBounds(const Scene& s) {
  SceneBox b;
  s.bounds(b.lo, b.hi);
  const float3 margin = (b.hi - b.lo) * 0.25f;
  b.lo = b.lo - margin;
  b.hi = b.hi + margin;
  return b;
}

// Every ray kind built on the host: incoherent, grazing, through vertices, along edges.
std::map<std::string, Rays> hostRays(const Scene& s, size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::uniform_int_distribution<size_t> pick(0, s.triangleCount() - 1);
  const SceneBox box = expandedBounds(s);
  std::map<std::string, Rays> kinds;
  for (size_t i = 0; i < n; ++i) {
    kinds["incoherent"].add(box.random(rng), randomDirection(rng));

    // Grazing: nearly parallel to a triangle's plane, aimed inside it.
    const size_t t = pick(rng);
    const float3 e1 = s.corner(t, 1) - s.corner(t, 0), e2 = s.corner(t, 2) - s.corner(t, 0);
    const float3 nrm = cross(e1, e2);
    if (length(nrm) > 0.f) {
      const float3 normal = normalize(nrm), inPlane = normalize(e1 * (u(rng) - 0.5f) + e2 * (u(rng) - 0.5f));
      const float3 d = normalize(inPlane + normal * ((u(rng) - 0.5f) * 2e-3f));
      const float su = std::sqrt(u(rng));
      const float3 target = pointOnTriangle(s, t, su * u(rng), 1.f - su);
      const float reach = length(box.hi - box.lo);
      kinds["grazing"].add(target - d * (0.5f * reach), d);
    }

    // Exactly through a vertex, and through a point on an edge.
    const float3 vertex = s.corner(pick(rng), int(i % 3));
    const float3 from = box.random(rng);
    if (length(vertex - from) > 0.f) kinds["vertices"].add(from, normalize(vertex - from));
    const size_t te = pick(rng);
    const int k = int(i % 3);
    const float a = u(rng);
    const float3 onEdge = s.corner(te, k) * (1.f - a) + s.corner(te, (k + 1) % 3) * a;
    const float3 from2 = box.random(rng);
    if (length(onEdge - from2) > 0.f) kinds["edges"].add(from2, normalize(onEdge - from2));
  }
  return kinds;
}

struct ScenePath {
  const char* path;
  size_t raysPerKind;
};

class AgainstBruteForce : public ::testing::TestWithParam<ScenePath> {};

void PrintTo(const ScenePath& p, std::ostream* os) { *os << p.path; }

TEST_P(AgainstBruteForce, EveryRayKindAgrees) {
  const Scene scene = loadScene(test::testScene(GetParam().path));
  const size_t n = GetParam().raysPerKind;
  RayCasting rc(scene);
  Camera camera = scene.hasCamera ? scene.camera : Camera{};
  if (!scene.hasCamera) {
    Vec3f lo, hi;
    scene.bounds(lo, hi);
    camera = frameBounds(lo, hi);
  }
  const int side = int(std::sqrt(double(n)));
  const RayQueue primary = rc.work.primary(camera, side, side, 7);
  rc.expectMatchesReference(rc.download(primary), "coherent (camera)");
  const cl::Buffer hits = rc.work.closestHits(primary);
  rc.expectMatchesReference(rc.download(rc.work.bounce(primary, hits, 11)), "from surfaces (bounce)");
  if (!scene.lights.empty())
    rc.expectMatchesReference(rc.download(rc.work.shadow(primary, hits, 13)), "from surfaces (shadow)");
  for (const auto& [kind, rays] : hostRays(scene, n, 17)) rc.expectMatchesReference(rays, kind);
}

std::string scenePathName(const ::testing::TestParamInfo<ScenePath>& info) {
  std::string name = info.param.path;
  name = name.substr(name.rfind('/') + 1);
  name = name.substr(0, name.find('.'));
  if (std::string(info.param.path).find("legacy") != std::string::npos) name = "Legacy" + name;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

// Fewer rays on the big scenes: the reference tests every triangle for every ray.
INSTANTIATE_TEST_SUITE_P(
    Corpus, AgainstBruteForce,
    ::testing::Values(ScenePath{"cornell-box/CornellBox-Original.obj", 4096},
                      ScenePath{"cornell-box/CornellBox-Mirror.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Empty-RG.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Empty-CO.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Empty-White.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Empty-Squashed.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Sphere.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Water.obj", 400},
                      ScenePath{"cornell-box/CornellBox-Glossy.obj", 1024},
                      ScenePath{"cornell-box/CornellBox-Glossy-Floor.obj", 256},
                      ScenePath{"cornell-box/water.obj", 400},
                      ScenePath{"cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj", 400},
                      ScenePath{"blob/blob.obj", 100},
                      ScenePath{"blob/CornellBox-Blob.obj", 100},
                      ScenePath{"mori-knob/testObj.obj", 256},
                      ScenePath{"colonnade/colonnade.obj", 256},
                      ScenePath{"veach/veach-plates.obj", 256}),
    scenePathName);

// ---- Closed meshes and scene scales ----

// An icosphere (subdivided icosahedron): closed, every edge shared by two triangles.
Scene icosphere(int subdivisions, float scale, const float3& offset) {
  const IndexedMesh mesh = fh::icosphere(subdivisions);
  const auto& v = mesh.vertices;
  const auto& f = mesh.faces;
  Scene scene;
  for (const auto& p : v) {
    const float3 q = p * scale + offset;
    scene.positions.insert(scene.positions.end(), q.begin(), q.end());
  }
  for (const auto& t : f) {
    scene.indices.insert(scene.indices.end(), t.begin(), t.end());
    scene.triangleMaterial.push_back(0);
  }
  scene.materials.push_back(Material{});
  return scene;
}

// The same scene scaled about the origin, then translated.
Scene transformed(Scene s, float scale, const float3& offset) {
  for (size_t i = 0; i < s.positions.size(); ++i) s.positions[i] = s.positions[i] * scale + offset[i % 3];
  s.camera.eye = s.camera.eye * scale + offset;
  s.camera.target = s.camera.target * scale + offset;
  return s;
}

struct Placement {
  float scale;
  float3 offset;
};

const Placement kPlacements[] = {
    {1.f, {0, 0, 0}},      {1e-3f, {0, 0, 0}},           {1e4f, {0, 0, 0}},
    {1.f, {1e4f, -2e4f, 3e4f}}, {1e-3f, {10.f, 20.f, -30.f}}, {1e4f, {1e8f, 0.f, -1e8f}},
};

std::string placementName(const Placement& p) {
  std::ostringstream s;
  s << "scale " << p.scale << " offset (" << p.offset[0] << "," << p.offset[1] << "," << p.offset[2] << ")";
  return s.str();
}

// The parallel build forks subtrees onto threads and grafts them where a serial build puts
// them: the same tree, bit for bit, for any thread count (so images do not depend on the
// machine's cores), and the SAH cost it reports is that tree's.
TEST(BvhBuild, TheSameTreeOnAnyNumberOfThreads) {
  const Scene scene = loadScene(test::testScene("blob/CornellBox-Blob.obj"));
  const Bvh serial = buildBvh(scene, {1});
  // The blob's overlapping triangles take spatial splits, whose pieces must graft too.
  EXPECT_GT(serial.stats.references, scene.triangleCount());
  for (unsigned threads : {2u, 3u, 8u}) {
    const Bvh parallel = buildBvh(scene, {threads});
    EXPECT_EQ(parallel.order, serial.order) << threads;
    ASSERT_EQ(parallel.nodes.size(), serial.nodes.size()) << threads;
    ASSERT_EQ(parallel.blocks.size(), serial.blocks.size()) << threads;
    EXPECT_EQ(std::memcmp(parallel.nodes.data(), serial.nodes.data(), serial.nodes.size() * sizeof(gpu::Bvh8Node)), 0);
    EXPECT_EQ(std::memcmp(parallel.blocks.data(), serial.blocks.data(),
                          serial.blocks.size() * sizeof(gpu::TriangleBlock8)), 0);
    EXPECT_EQ(parallel.stats.sahCost, serial.stats.sahCost);
  }
  // A tree's SAH cost is at least a root visit plus testing a ray's share of every triangle
  // once, and below testing them all.
  EXPECT_GT(serial.stats.sahCost, 1.0);
  EXPECT_LT(serial.stats.sahCost, 0.15 * double(scene.triangleCount()));
}

// The 8-wide tree is planned by dynamic programming over the binary tree (bvh.cpp,
// WideCollapser). The tree it emits must be the plan it costed: its cost, recomputed from
// the nodes' child boxes (a wide node visit 1, a leaf block 1.2, by area over the root's),
// is the cost the build reports. Each leaf block holds each triangle once, and every
// triangle is in some block.
TEST(BvhBuild, TheWideTreeIsThePlanItCosted) {
  for (const char* file : {"blob/CornellBox-Blob.obj", "colonnade/colonnade.obj"}) {
    const Scene scene = loadScene(test::testScene(file));
    const Bvh bvh = buildBvh(scene);
    auto extent = [](const gpu::Bvh8Node& n, int i) {
      return std::array<double, 3>{double(n.hi_x[i]) - n.lo_x[i], double(n.hi_y[i]) - n.lo_y[i],
                                   double(n.hi_z[i]) - n.lo_z[i]};
    };
    auto area = [&](const gpu::Bvh8Node& n, int i) {
      const auto [x, y, z] = extent(n, i);
      return 2.0 * (x * y + y * z + z * x);
    };
    auto volume = [&](const gpu::Bvh8Node& n, int i) {
      const auto [x, y, z] = extent(n, i);
      return x * y * z;
    };
    gpu::Bvh8Node root = bvh.nodes[0];
    for (int i = 1; i < 8; ++i) {
      if (root.child[i] == 0) continue;
      root.lo_x[0] = std::min(root.lo_x[0], root.lo_x[i]), root.hi_x[0] = std::max(root.hi_x[0], root.hi_x[i]);
      root.lo_y[0] = std::min(root.lo_y[0], root.lo_y[i]), root.hi_y[0] = std::max(root.hi_y[0], root.hi_y[i]);
      root.lo_z[0] = std::min(root.lo_z[0], root.lo_z[i]), root.hi_z[0] = std::max(root.hi_z[0], root.hi_z[i]);
    }
    const double rootArea = area(root, 0), rootVolume = volume(root, 0);
    ASSERT_GT(rootVolume, 0.0) << file;
    double cost = 1.0;
    for (const gpu::Bvh8Node& n : bvh.nodes)
      for (int i = 0; i < 8; ++i)
        if (n.child[i] != 0)
          cost += (n.child[i] > 0 ? 1.0 : 1.2) * (area(n, i) / rootArea + volume(n, i) / rootVolume);
    EXPECT_NEAR(cost, bvh.stats.wideSahCost, 1e-4 * cost) << file;

    std::vector<int> blocksHolding(scene.triangleCount(), 0);
    for (const gpu::TriangleBlock8& b : bvh.blocks) {
      std::set<int> ids;
      for (int lane = 0; lane < 8; ++lane)
        if (b.id[lane] >= 0) {
          EXPECT_TRUE(ids.insert(b.id[lane]).second) << file << ": triangle " << b.id[lane] << " twice in a block";
          ++blocksHolding[size_t(b.id[lane])];
        }
    }
    EXPECT_EQ(std::count(blocksHolding.begin(), blocksHolding.end(), 0), 0) << file;
  }
}

// Rays that start inside a room visit every box they start in. The Cornell box's floor,
// walls and ceiling are flat boxes apart; gathered into one leaf block (eight triangles,
// tested at once, "free" by the area ratio alone), they make a box the size of the room
// that nearly every bounce and shadow ray visits. The plan's volume term (bvh.cpp:
// kVolumeWeight) keeps them apart: no leaf holds a quarter of the room's volume.
TEST(BvhBuild, NoLeafSpansTheRoom) {
  const Scene scene = loadScene(test::projectScene("cornell-box/CornellBox-Original.obj"));
  const Bvh bvh = buildBvh(scene);
  const std::array<float, 3> lo = {-1.02f, 0.0f, -1.04f}, hi = {1.0f, 1.99f, 0.99f};  // the room, from the OBJ
  const double room = double(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  int leaves = 0;
  for (const gpu::Bvh8Node& n : bvh.nodes)
    for (int i = 0; i < 8; ++i) {
      if (n.child[i] >= 0) continue;
      ++leaves;
      const double volume =
          double(n.hi_x[i] - n.lo_x[i]) * double(n.hi_y[i] - n.lo_y[i]) * double(n.hi_z[i] - n.lo_z[i]);
      EXPECT_LT(volume, 0.25 * room) << "leaf " << ~n.child[i];
    }
  EXPECT_EQ(leaves, int(bvh.blocks.size()));
}

// Spatial splits cut the long, overlapping triangles of a Sponza-like scene: the tree holds
// more references than triangles, within the budget, and costs less by the SAH than object
// splits alone, while each triangle keeps one index in BVH order. Rays aimed at points
// spread over the cut triangles, where a piece's clipped box could leave a gap, all find
// what the brute-force reference finds.
TEST(BvhBuild, SpatialSplitsCutLongTrianglesWithoutGaps) {
  const Scene scene = loadScene(test::testScene("colonnade/colonnade.obj"));
  const size_t n = scene.triangleCount();
  const Bvh objectsOnly = buildBvh(scene, {0, 0.f});
  const BvhOptions options;
  const Bvh split = buildBvh(scene, options);
  EXPECT_EQ(objectsOnly.stats.references, n);
  EXPECT_GT(split.stats.references, n);
  EXPECT_LE(double(split.stats.references), double(n) * (1.0 + double(options.spatialSplitBudget)));
  EXPECT_LT(split.stats.sahCost, objectsOnly.stats.sahCost);

  std::vector<unsigned> sorted = split.order;
  std::sort(sorted.begin(), sorted.end());
  for (size_t k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k) << "BVH order is not a permutation";
  std::vector<int> leavesOf(n, 0);
  size_t lanes = 0;
  for (const gpu::TriangleBlock8& block : split.blocks)
    for (int id : block.id)
      if (id >= 0) {
        ASSERT_LT(size_t(id), n);
        ++leavesOf[size_t(id)];
        ++lanes;
      }
  EXPECT_EQ(lanes, split.stats.references);

  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const SceneBox box = expandedBounds(scene);
  Rays rays;
  for (size_t k = 0; k < n; ++k) {
    if (leavesOf[k] < 2) continue;
    const size_t t = split.order[k];
    for (int i = 0; i < 8; ++i) {
      const float su = std::sqrt(u(rng));
      const float3 target = pointOnTriangle(scene, t, su * u(rng), 1.f - su), from = box.random(rng);
      if (length(target - from) > 0.f) rays.add(from, normalize(target - from));
    }
  }
  ASSERT_GT(rays.size(), 100u);
  RayCasting rc(scene);
  rc.expectMatchesReference(rays, "aimed at triangles cut by spatial splits");
}

// Rays set up eight at once (precompute_rays8: the megakernel's lanes, the shadow stage's)
// must get every constant precompute_ray gives each alone, bit for bit, or the strategies'
// images part: directions with zero and negative-zero components, components of equal
// size (the dominant-axis choice's ties), denormals, and origins on either side of 1.
TEST(RayConstants, EightRaysAtOnceGetEachRaysOwnBits) {
  const char* kernel = R"CL(
FH_INLINE void put(__global uint* out, RayPrecomp r) {
  const uint v[21] = {as_uint(r.inv_dir.x), as_uint(r.inv_dir.y), as_uint(r.inv_dir.z), r.near_x, r.near_y,
                      r.near_z, as_uint(r.near_offset.x), as_uint(r.near_offset.y), as_uint(r.near_offset.z),
                      as_uint(r.far_offset.x), as_uint(r.far_offset.y), as_uint(r.far_offset.z), r.kx, r.ky, r.kz,
                      as_uint(r.sx), as_uint(r.sy), as_uint(r.sz), as_uint(r.ox), as_uint(r.oy), as_uint(r.oz)};
  for (int k = 0; k < 21; ++k) out[k] = v[k];
}
__kernel void constants(__global const float4* org, __global const float4* dir, __global uint* alone,
                        __global uint* together) {
  const uint first = get_global_id(0) * 8;
  float o[3][8], d[3][8];
  for (int l = 0; l < 8; ++l) {
    put(alone + 21 * (first + l), precompute_ray(org[first + l].xyz, dir[first + l].xyz));
    for (int a = 0; a < 3; ++a) {
      o[a][l] = org[first + l][a];
      d[a][l] = dir[first + l][a];
    }
  }
  RayPrecomp8 eight;
  precompute_rays8(vload8(0, o[0]), vload8(0, o[1]), vload8(0, o[2]), vload8(0, d[0]), vload8(0, d[1]),
                   vload8(0, d[2]), &eight);
  for (int l = 0; l < 8; ++l) put(together + 21 * (first + l), ray_of_lane(&eight, l));
}
)CL";
  DeviceContext& dc = test::defaultDevice();
  const cl::Program program =
      buildProgramFromSource(dc.context, dc.info.device, assembleKernelSources({"intersect.h"}) + kernel, "");
  const float special[] = {0.f, -0.f, 1.f, -1.f, 0.5f, -0.5f, 1e-31f, -1e-31f, 1e-40f, 3.f};
  Rays rays;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-4.f, 4.f);
  std::uniform_int_distribution<size_t> pick(0, std::size(special) - 1);
  for (int i = 0; i < 4096; ++i) {
    float3 d{}, o{};
    for (size_t a = 0; a < 3; ++a) {
      d[a] = i % 2 ? special[pick(rng)] : u(rng);
      o[a] = i % 3 ? u(rng) * 100.f : special[pick(rng)];
    }
    if (d[0] == 0.f && d[1] == 0.f && d[2] == 0.f) d[1] = -2.f;  // a ray needs a direction
    rays.add(o, d);
  }
  const size_t n = rays.size(), words = 21 * n * sizeof(cl_uint);
  cl::Buffer org = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, n * 16, "origins", rays.org.data());
  cl::Buffer dir = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, n * 16, "directions", rays.dir.data());
  cl::Buffer alone = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, words, "one at a time");
  cl::Buffer together = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, words, "eight at once");
  cl::Kernel k = createKernel(program, "constants");
  setKernelArgs(k, org, dir, alone, together);
  FH_CL(dc.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n / 8)));
  std::vector<cl_uint> a(21 * n), t(21 * n);
  FH_CL(dc.queue.enqueueReadBuffer(alone, CL_TRUE, 0, words, a.data()));
  FH_CL(dc.queue.enqueueReadBuffer(together, CL_TRUE, 0, words, t.data()));
  size_t differ = 0, first = 0;
  for (size_t w = 0; w < a.size(); ++w)
    if (a[w] != t[w]) first = differ++ ? first : w;
  EXPECT_EQ(differ, 0u) << "first: ray " << first / 21 << ", constant " << first % 21 << ": " << a[first] << " vs "
                        << t[first];
}

TEST(Watertight, RaysAtSharedEdgesAndVerticesNeverMiss) {
  for (const Placement& p : kPlacements) {
    const float3 center = p.offset;
    const Scene sphere = icosphere(3, p.scale, center);
    RayCasting rc(sphere);
    Rays inside, outside;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (size_t t = 0; t < sphere.triangleCount(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const float3 a = sphere.corner(t, k), b = sphere.corner(t, (k + 1) % 3);
        const float3 mid = (a + b) * 0.5f, vertex = a;
        // From inside (the centre and a random inner point) every direction must hit.
        inside.add(center, normalize(vertex - center));
        inside.add(center, normalize(mid - center));
        const float3 inner = center + randomDirection(rng) * (0.5f * p.scale * u(rng));
        inside.add(inner, normalize(mid - inner));
        // From outside, at a point that sees the edge's front.
        const float3 from = center + normalize(mid - center) * (3.f * p.scale) + randomDirection(rng) * (0.5f * p.scale);
        outside.add(from, normalize(mid - from));
        outside.add(from, normalize(vertex - from));
      }
    }
    const std::string name = placementName(p);
    rc.expectMatchesReference(inside, "inside, " + name);
    EXPECT_EQ(rc.lastHitFraction, 1.0) << "rays from inside a closed mesh escaped: " << name;
    rc.expectMatchesReference(outside, "outside, " + name);
    EXPECT_EQ(rc.lastHitFraction, 1.0) << "rays at front-facing edges and vertices missed: " << name;
  }
}

// Axis-aligned geometry and rays, as in a box scene seen straight on: the edge functions
// of a ray through a shared edge or vertex are exactly zero, the case the watertight test
// must count as inside for one triangle of every pair (a planted bug once: a one-sided `<=` there
// passed every other test and left seams where walls meet). Each axis-aligned face of a
// grid is hit through its vertices, edge midpoints and diagonals, from its front, along
// each axis.
TEST(Watertight, AxisAlignedRaysThroughEdgesAndVerticesOfAGridNeverMiss) {
  test::SceneBuilder b;
  const int m = b.material(0.5f), cells = 6;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j) {
        // A cell of the plane {axis} = 0, its front toward +{axis}, offset along the axis
        // per plane so the three grids do not overlap.
        auto at = [&](float u, float v) {
          float3 p{};
          p[size_t(axis)] = 10.f * float(axis);
          p[size_t((axis + 1) % 3)] = u;
          p[size_t((axis + 2) % 3)] = v;
          return p;
        };
        float3 toward = at(float(i) + 0.5f, float(j) + 0.5f);
        toward[size_t(axis)] += 1.f;
        b.quadFacing(at(float(i), float(j)), at(float(i + 1), float(j)), at(float(i + 1), float(j + 1)),
                     at(float(i), float(j + 1)), toward, m);
      }
  const Scene grid = b.build();
  RayCasting rc(grid);
  Rays rays;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i <= 2 * cells; ++i)
      for (int j = 0; j <= 2 * cells; ++j) {
        // Half-integer steps: vertices, edge midpoints, cell centres (on a diagonal).
        float3 o{}, d{};
        o[size_t(axis)] = 10.f * float(axis) + 2.f;
        o[size_t((axis + 1) % 3)] = 0.5f * float(i);
        o[size_t((axis + 2) % 3)] = 0.5f * float(j);
        d[size_t(axis)] = -1.f;
        rays.add(o, d);
      }
  rc.expectMatchesReference(rays, "axis-aligned grid");
  EXPECT_EQ(rc.lastHitFraction, 1.0) << "axis-aligned rays through shared edges or vertices missed";
}

// Triangles at exactly the current hit's distance in a later leaf (duplicated faces, as in
// the archive's Cornell box, or overlapping ones) must leave the hit and its barycentrics
// as they were: a lane that passes the division-free interval test but whose quotient t
// equals t_max once selected no lane, and the kernel read its barycentrics from index -1.
TEST(CoincidentTriangles, HitsKeepTheirOwnTriangleAndBarycentrics) {
  // A slanted quad copied twelve times (more than one leaf holds), and a grid of slanted
  // quads whose shared edges cross leaves.
  test::SceneBuilder builder;
  test::coincidentQuads(builder, 12, builder.material(0.5f));
  Scene copies = builder.build();
  Scene grid;
  grid.materials.push_back(Material{});
  const int cells = 24;
  auto gridPoint = [&](int i, int j) {
    const float x = -1.f + 2.f * float(i) / cells, y = -1.f + 2.f * float(j) / cells;
    return float3{x, y, 0.37f * x - 0.21f * y + 0.05f * x * y};
  };
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const unsigned base = unsigned(grid.vertexCount());
      for (const float3& p : {gridPoint(i, j), gridPoint(i + 1, j), gridPoint(i + 1, j + 1), gridPoint(i, j + 1)})
        grid.positions.insert(grid.positions.end(), p.begin(), p.end());
      for (unsigned k : {0u, 1u, 2u, 0u, 2u, 3u}) grid.indices.push_back(base + k);
      grid.triangleMaterial.insert(grid.triangleMaterial.end(), {0, 0});
    }

  for (const Scene* scene : {&copies, &grid}) {
    RayCasting rc(*scene);
    Rays rays;
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int i = 0; i < 4096; ++i) {
      // Aimed at a random point, a vertex or a point on an edge, from either side.
      const size_t t = size_t(i) % scene->triangleCount();
      const int k = i % 3;
      const float a = u(rng), b = u(rng);
      float3 target;
      switch ((i / 3) % 3) {
        case 0: target = pointOnTriangle(*scene, t, a * (1.f - b), b * (1.f - a)); break;
        case 1: target = scene->corner(t, k); break;
        default: target = scene->corner(t, k) * (1.f - a) + scene->corner(t, (k + 1) % 3) * a; break;
      }
      const float3 from = target + randomDirection(rng) * (0.5f + 3.f * u(rng));
      rays.add(from, normalize(target - from));
    }
    rc.expectMatchesReference(rays, scene == &copies ? "twelve copies of a quad" : "grid of shared edges");
    EXPECT_GT(rc.lastHitFraction, 0.6);  // rays at the border of the mesh may miss
  }
}

// Bounce and shadow rays spawned from hits never hit the triangle they leave, and
// shadow rays never hit the light triangle they aim at.
TEST(SelfIntersection, SpawnedRaysNeverReHitTheirTriangleAtAnyScale) {
  const Scene base = loadDefaultScene();
  for (const Placement& p : kPlacements) {
    const Scene scene = transformed(base, p.scale, p.offset);
    RayCasting rc(scene);
    const RayQueue primary = rc.work.primary(scene.camera, 96, 96, 3);
    const cl::Buffer primaryHits = rc.work.closestHits(primary);
    const std::vector<float> firstHits = rc.work.readFloat4(primaryHits, primary.count);
    for (int kind = 0; kind < 2; ++kind) {
      const RayQueue spawned =
          kind == 0 ? rc.work.bounce(primary, primaryHits, 21) : rc.work.shadow(primary, primaryHits, 23);
      ASSERT_GT(spawned.count, primary.count / 2) << placementName(p);
      const std::vector<float> hits = rc.work.readFloat4(rc.work.closestHits(spawned), spawned.count);
      const std::vector<unsigned> source = rc.work.readUints(spawned.source, spawned.count);
      size_t selfHits = 0, escaped = 0;
      for (size_t i = 0; i < spawned.count; ++i) {
        int from, to;
        std::memcpy(&from, &firstHits[4 * source[i] + 3], 4);
        std::memcpy(&to, &hits[4 * i + 3], 4);
        selfHits += to == from;
        escaped += kind == 0 && to < 0;
      }
      EXPECT_EQ(selfHits, 0u) << (kind == 0 ? "bounce" : "shadow") << " rays, " << placementName(p);
      // The box is open only at the front: most bounces stay inside.
      if (kind == 0) {
        EXPECT_LT(escaped, spawned.count / 2) << placementName(p);
      }
    }
  }
}

}  // namespace
}  // namespace fh
