// Helpers shared by the tests (one library, fredholm_test_support, linked by every test
// executable): the device, render settings and renders, paths, temporary directories,
// running the CLI, brute-force ray oracles.
#pragma once
#include <cmath>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "device/device_context.h"
#include "render/film.h"
#include "render/render.h"
#include "render/settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh::test {

// The first device (fredholm's default), set up once per test process: the rendering tests
// share its context, so kernels compile once.
DeviceContext& defaultDevice();

// RenderSettings{} with the strategy this run tests: FREDHOLM_TEST_STRATEGY (CTest runs the
// rendering suites under several, tests/CMakeLists.txt; base/test_hooks.h), else auto.
RenderSettings renderSettings();

// `scene` seen by `camera`, rendered on defaultDevice() (its BVH built here). The one render
// call the rendering suites share; what differs goes in the settings, by name:
//   RenderSettings s = test::renderSettings();
//   s.method = Method::PT;
//   s.spp = 256;
//   const RenderResult r = test::render(scene, camera, s);
RenderResult render(const Scene& scene, const Camera& camera, const RenderSettings& settings);

// Absolute path of a file in this repository's scenes/.
std::string projectScene(const std::string& relative);
// Absolute path of a file among the scenes generated at build time (tests/make_test_scenes.cpp),
// which stand in for scenes that may not be redistributed; manifest.json lists their counts.
std::string generatedScene(const std::string& relative);
// A scene of the test corpus: shipped in scenes/ or else generated.
std::string testScene(const std::string& relative);

// A fresh empty directory under the system temp dir, removed at exit.
std::string tempDir(const std::string& tag);

// Every channel of an EXR (the image and its layers), as stored, pixel by pixel; `names`
// gets the channels' names.
std::vector<float> exrChannels(const std::string& path, std::vector<std::string>* names = nullptr);
void writeFile(const std::string& path, const std::string& text);

struct CommandResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};
// Runs a shell command line, stdout and stderr together.
CommandResult runCommand(const std::string& command);
// The JSON file at `path` (a --stats or --json output); an unreadable file fails the parse.
nlohmann::json readJson(const std::string& path);
// Runs the fredholm binary with `args` (a shell-quoted string) and optional environment prefix.
CommandResult runFredholm(const std::string& args, const std::string& env = "");

// A film of `side`² pixels of value 0.5 in `passes` passes of two replicates, each sample
// with Gaussian noise of deviation `sigma`, or `regionSigma` at the pixels (x, y) where
// `inRegion` is true.
Film noisyFilm(int side, int passes, double sigma, double regionSigma, const std::function<bool(int, int)>& inRegion,
               unsigned seed);
// A pass of that film's size with every sample 0.5 but at `pixels`, `value` there.
std::vector<float> passWithFireflies(const Film& film, const std::vector<size_t>& pixels, float value);

// Writes a small scene into `dir` that reaches every material feature the kernels have:
// a textured floor (map_Kd, UVs), glossy and mirror walls, a glass prism, a wall with
// shading normals and a light; returns the OBJ's path (camera JSON beside it).
std::string writeFeatureScene(const std::string& dir);

// A copy of the OBJ at `obj` and its camera with every length (and every normal, which need
// not be of unit length) times 2^exponent (exactly),
// beside it as NAME-scaledEXPONENT.obj; returns its path.
std::string writeScaledCopy(const std::string& obj, int exponent);

}  // namespace fh::test

namespace fh::test {

// Closest hit by testing every triangle (double-precision Moller-Trumbore): the
// reference the device kernels are compared with. triangle is -1 on a miss.
struct BruteHit {
  double t = INFINITY;
  long triangle = -1;
};
BruteHit bruteForceClosest(const Scene& scene, const double org[3], const double dir[3], double tMin = 0.0,
                           double tMax = INFINITY);

// Ray/triangle distance in double precision (Moller-Trumbore); INFINITY on a miss.
double rayTriangle(const Scene& scene, size_t triangle, const double org[3], const double dir[3]);

// The same with the triangle grown (margin > 0) or shrunk (margin < 0) by |margin|,
// a distance measured across the ray: the ray counts as hitting the grown triangle when
// it passes within `margin` of one of its edges.
double rayTriangleWithMargin(const Scene& scene, size_t triangle, const double org[3], const double dir[3],
                             double margin);

// How far a float ray/triangle test may misjudge the ray's distance to an edge: a few
// dozen ulps of the magnitudes it subtracts (vertex - origin, then the shear).
double floatEdgeMargin(const Scene& scene, size_t triangle, const double org[3]);

// The closest hit in [tMin, tMax) of three oracles at once: triangles as they are, grown
// and shrunk by floatEdgeMargin. A correct float kernel's answer lies between shrunk and
// grown.
struct BruteHits {
  BruteHit exact, grown, shrunk;
};
BruteHits bruteForceBands(const Scene& scene, const double org[3], const double dir[3], double tMin, double tMax);

}  // namespace fh::test
