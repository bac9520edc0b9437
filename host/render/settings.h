// What a render is asked to do: size, budget, method, filter and the knobs the path
// tracer exposes. Parsed and checked by the command line (host/cli), used by every layer
// of a render.
#pragma once
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace fh {

struct EnvironmentMap;
struct Film;
class FilmWatcher;
class PassLedger;

// pt, nee and mis trace paths from the camera (render/wavefront.h); lt traces them from the
// lights and connects each vertex to the camera, bdpt traces both and joins them, and vcm
// also merges light vertices near camera vertices (render/light_tracer.h).
enum class Method { PT, NEE, MIS, LT, BDPT, VCM };
const char* methodName(Method m);
// lt, bdpt and vcm: paths from the emitting triangles, splatted where the camera sees them.
inline bool tracesLightPaths(Method m) { return m == Method::LT || m == Method::BDPT || m == Method::VCM; }
// bdpt and vcm: camera subpaths joined to light subpaths.
inline bool bidirectional(Method m) { return m == Method::BDPT || m == Method::VCM; }

enum class PixelFilter { Box, Gaussian, BlackmanHarris };
const char* filterName(PixelFilter f);

// How a device runs the stages: as a wavefront of kernels over queues with one path per
// work-item (Scalar: GPUs) or eight in vector lanes (Simd8; PoCL does not vectorize
// divergent shading across work-items, kernels/lanes.h), or all in one kernel that loops
// over the stages for one path per work-item (Megakernel) or eight (Megakernel8: CPUs,
// whose caches keep a path's state close while a wavefront streams it through memory).
// All compute the same estimator.
enum class Strategy { Auto, Scalar, Simd8, Megakernel, Megakernel8 };
const char* strategyName(Strategy s);

// Passes before a noise target is checked: fewer samples estimate a pixel's variance too
// poorly (a light found once or not yet).
constexpr unsigned kNoiseMinPasses = 16;

struct RenderSettings {
  int width = 512, height = 512;
  int spp = 64;          // samples per pixel; with seconds > 0, the most to take
  // --passes A:B renders only the chunk of passes firstPass (A) .. spp - 1 (B = spp), into a
  // film that merges with the other chunks' (fredholm merge) into the image of all of them.
  uint32_t firstPass = 0;
  double seconds = 0.0;  // time budget: stop at the end of the pass running when it is spent
  // With a time budget, the passes rendered however soon it is spent (a render of nothing
  // answers no one's question; --method auto's pilots need a noise estimate's worth).
  uint32_t minPasses = 1;
  // Noise target: stop once the film's estimated relMSE (Film::estimatedRelMse) is at most
  // this, checked after each pass from kNoiseMinPasses on; 0: none.
  double noise = 0.0;
  // The sampler's independently scrambled sequences (RenderParams::replicates): two under a
  // noise target, whose difference is its error estimate; else one.
  unsigned replicates() const { return noise > 0.0 ? 2 : 1; }
  // --adaptive: after a first round over every pixel, passes cover the pixels where the
  // error is (render/adaptive.h); spp is then the average over the image, a budget.
  bool adaptive = false;
  Method method = Method::MIS;
  int maxDepth = 64;     // bounces; Russian roulette does the real work
  // Russian roulette from this bounce on: later than the minimum because roulette adds
  // variance that, in closed scenes, costs more than the extra bounces (bench/RESULTS.md).
  int rrDepth = 6;
  // vcm: the first pass's merging radius as a fraction of the scene's bounding radius
  // (render/merge_grid.h shrinks it pass by pass).
  float mergeRadius = 0.01f;
  unsigned seed = 1;
  // The scene's radiance per renderer radiance (render/radiance_unit.h) and its lengths per
  // renderer length (1 / Scene::worldScale, for the depth layer): the film's units.
  double radianceUnit = 1.0, depthUnit = 1.0;
  std::array<float, 3> env{0.f, 0.f, 0.f};  // --env: constant radiance, found by BSDF sampling only
  // --env-map: an HDR map lighting the scene, sampled like the triangle lights; null: none.
  std::shared_ptr<const EnvironmentMap> envMap;
  PixelFilter filter = PixelFilter::Box;
  size_t wavefront = 0;  // paths in flight per device; 0: chosen for each device
  bool progress = false;
  bool allFeatures = false;  // compile every material feature, not only the scene's (benchmarks)
  Strategy strategy = Strategy::Auto;  // Auto: chosen per device type
  // Record each sample's first-surface layers (albedo, normal, depth: kernels/aovs.h) in the
  // same render; the film then keeps them beside the radiance (render/film.h).
  bool surfaceAovs = false;
  // --checkpoint: the film (passes merged in order) saved to this file every
  // checkpointSeconds and when the render ends, with the render's fingerprint
  // (render/checkpoint.h); empty: none.
  std::string checkpointPath;
  double checkpointSeconds = 60.0;
  std::string fingerprint;
};

// What a render is wired to while it runs, apart from the values above that say what it
// computes: the film it goes on from, who hands out its passes, who watches, what stops it.
struct RenderLinks {
  // --resume: a saved film to go on from (it holds passes 0 .. resume->passes() - 1).
  std::shared_ptr<const Film> resume;
  // Where new passes come from when several processes share the render (render/pass_ledger.h;
  // the ledger then owns the sample count and time budget); null: the pool counts them. The
  // film then holds whichever passes this process rendered, added as they finish (its sums
  // are exact, render/film.h, so the order does not matter but for sumSq's rounding).
  PassLedger* ledger = nullptr;
  // Shown the film between merged passes when it asks (render/film_watcher.h); null: none.
  FilmWatcher* watcher = nullptr;
  // Set (non-zero) to stop early, as Ctrl-C does: passes in flight are dropped, those
  // finished are kept. Null: never.
  const std::atomic<int>* stop = nullptr;
  bool stopRequested() const { return stop && stop->load() != 0; }
};

}  // namespace fh
