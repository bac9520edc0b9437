// The helpers shared by the tests (test_support.h).
#include "test_support.h"

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "accel/bvh.h"
#include "base/test_hooks.h"
#include "cli/flags.h"
#include "device/devices.h"
#include "image/image_io.h"

namespace fh::test {

DeviceContext& defaultDevice() {
  static DeviceContext dc(selectDevices(listDevices(), "").front());
  return dc;
}

RenderSettings renderSettings() {
  RenderSettings s;
  if (const std::string& strategy = testHooks().testStrategy; !strategy.empty()) s.strategy = parseStrategy(strategy);
  return s;
}

RenderResult render(const Scene& scene, const Camera& camera, const RenderSettings& settings) {
  const Bvh bvh = buildBvh(scene);
  return fh::render(defaultDevice(), scene, bvh, camera, settings);
}

namespace fs = std::filesystem;

std::string generatedScene(const std::string& relative) {
  return std::string(FREDHOLM_TEST_SCENES) + "/" + relative;
}

std::string testScene(const std::string& relative) {
  const std::string shipped = projectScene(relative);
  return fs::exists(shipped) ? shipped : generatedScene(relative);
}

std::string projectScene(const std::string& relative) {
  return std::string(FREDHOLM_SOURCE_DIR) + "/scenes/" + relative;
}

namespace {
struct TempDirs {
  std::vector<fs::path> dirs;
  ~TempDirs() {
    std::error_code ec;
    for (const auto& d : dirs) fs::remove_all(d, ec);
  }
};
TempDirs& tempDirs() {
  static TempDirs dirs;
  return dirs;
}
}  // namespace

std::string tempDir(const std::string& tag) {
  std::string pattern = (fs::temp_directory_path() / ("fredholm-" + tag + "-XXXXXX")).string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  const char* made = mkdtemp(buf.data());
  if (!made) throw std::runtime_error("mkdtemp failed");
  tempDirs().dirs.emplace_back(made);
  return made;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

CommandResult runFredholm(const std::string& args, const std::string& env) {
  return runCommand(env + " " + FREDHOLM_BINARY + " " + args);
}

std::string writeFeatureScene(const std::string& dir) {
  Image texture;
  texture.width = texture.height = 4;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) texture.rgb.push_back(((x + y) % 2 ? 0.8f : 0.2f) * (c == y % 3 ? 1.f : 0.6f));
  writeImage(dir + "/checker.png", texture, {});
  writeFile(dir + "/features.mtl",
            "newmtl textured\nKd 1 1 1\nmap_Kd checker.png\n"
            "newmtl glossy\nillum 2\nKd 0.3 0.3 0.5\nKs 0.4 0.4 0.4\nNs 80\n"
            "newmtl mirror\nillum 3\nKd 0 0 0\nKs 0.9 0.9 0.9\nNs 2000\n"
            "newmtl glass\nillum 7\nKd 0 0 0\nKs 1 1 1\nNi 1.5\nTf 1 1 1\n"
            "newmtl smooth\nKd 0.6 0.5 0.4\n"
            "newmtl light\nKd 0 0 0\nKe 8 8 8\n");
  writeFile(dir + "/features.obj",
            "mtllib features.mtl\n"
            // Floor (y = 0, textured), back wall (z = -1, glossy), left wall (x = -1, mirror),
            // right wall (x = 1, shading normals), ceiling light (y = 2, facing down).
            "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
            "v -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n"
            "v -0.3 1.99 -0.3\nv 0.3 1.99 -0.3\nv 0.3 1.99 0.3\nv -0.3 1.99 0.3\n"
            // A glass tetrahedron on the floor.
            "v -0.4 0.01 0.1\nv 0.2 0.01 0.3\nv -0.1 0.01 -0.4\nv -0.1 0.6 0\n"
            "vt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\n"
            "vn -0.9 0.3 0\nvn -1 0 0.2\nvn -0.8 -0.2 0.1\n"
            "usemtl textured\nf 4/4 3/3 2/2 1/1\n"
            "usemtl glossy\nf 1 2 6 5\n"
            "usemtl mirror\nf 4 1 5 8\n"
            "usemtl smooth\nf 2//1 3//2 7//3\nf 2//1 7//3 6//2\n"
            "usemtl light\nf 9 10 11 12\n"
            "usemtl glass\nf 13 15 14\nf 13 14 16\nf 14 15 16\nf 15 13 16\n");
  writeFile(dir + "/features.camera.json",
            R"({"eye": [0, 1, 3.2], "target": [0, 0.9, 0], "up": [0, 1, 0], "fov_y_deg": 45})");
  return dir + "/features.obj";
}

// See test_support.h.
std::string writeScaledCopy(const std::string& obj, int exponent) {
  std::ifstream in(obj);
  std::ostringstream out;
  char number[3][32];
  for (std::string line; std::getline(in, line);) {
    // Positions, and normals too, which need not be of unit length.
    if (line.rfind("v ", 0) == 0 || line.rfind("vn ", 0) == 0) {
      const std::string kind = line.substr(0, line.find(' ') + 1);
      std::istringstream v(line.substr(kind.size()));
      float xyz[3];
      v >> xyz[0] >> xyz[1] >> xyz[2];
      for (int k = 0; k < 3; ++k) std::snprintf(number[k], sizeof number[k], "%.9g", std::ldexp(xyz[k], exponent));
      line = kind + number[0] + " " + number[1] + " " + number[2];
    }
    out << line << "\n";
  }
  const std::filesystem::path base = std::filesystem::path(obj).replace_extension();
  const std::string copy = base.string() + "-scaled" + std::to_string(exponent);
  writeFile(copy + ".obj", out.str());
  nlohmann::json camera = readJson(base.string() + ".camera.json");
  for (const char* key : {"eye", "target"})
    for (auto& x : camera[key]) x = std::ldexp(x.get<float>(), exponent);
  writeFile(copy + ".camera.json", camera.dump());
  return copy + ".obj";
}

CommandResult runCommand(const std::string& command_) {
  const std::string command = command_ + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace fh::test

namespace fh::test {

namespace {

struct D3 {
  double x, y, z;
};
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dotd(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 crossd(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double maxAbs(D3 a) { return std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}); }

D3 cornerD(const Scene& s, size_t t, int k) {
  const Vec3f p = s.corner(t, k);
  return {p[0], p[1], p[2]};
}

// Distance from the ray's line to segment (a, b), measured in the plane across the ray.
double distanceToEdge(D3 o, D3 dUnit, D3 a, D3 b) {
  auto project = [&](D3 p) { return (p - o) - dUnit * dotd(p - o, dUnit); };
  const D3 pa = project(a), pb = project(b), e = pb - pa;
  const double len2 = dotd(e, e);
  const double s = len2 > 0.0 ? std::clamp(-dotd(pa, e) / len2, 0.0, 1.0) : 0.0;
  const D3 closest = pa + e * s;
  return std::sqrt(dotd(closest, closest));
}

}  // namespace

double rayTriangle(const Scene& scene, size_t t, const double o[3], const double d[3]) {
  const D3 v0 = cornerD(scene, t, 0), v1 = cornerD(scene, t, 1), v2 = cornerD(scene, t, 2);
  const D3 dir{d[0], d[1], d[2]}, org{o[0], o[1], o[2]};
  const D3 e1 = v1 - v0, e2 = v2 - v0, p = crossd(dir, e2);
  const double det = dotd(e1, p);
  if (det == 0.0) return INFINITY;
  const D3 s = org - v0, q = crossd(s, e1);
  const double u = dotd(s, p) / det, w = dotd(dir, q) / det;
  if (u < 0.0 || w < 0.0 || u + w > 1.0) return INFINITY;
  return dotd(e2, q) / det;
}

double floatEdgeMargin(const Scene& scene, size_t t, const double o[3]) {
  const D3 org{o[0], o[1], o[2]};
  double reach = 0.0, size = maxAbs(org);
  for (int k = 0; k < 3; ++k) {
    reach = std::max(reach, maxAbs(cornerD(scene, t, k) - org));
    size = std::max(size, maxAbs(cornerD(scene, t, k)));
  }
  return std::ldexp(reach + size, -18);
}

double rayTriangleWithMargin(const Scene& scene, size_t t, const double o[3], const double d[3], double margin) {
  const double exact = rayTriangle(scene, t, o, d);
  if (margin == 0.0) return exact;
  const D3 v[3] = {cornerD(scene, t, 0), cornerD(scene, t, 1), cornerD(scene, t, 2)};
  const D3 org{o[0], o[1], o[2]}, dir{d[0], d[1], d[2]};
  const D3 dUnit = dir * (1.0 / std::sqrt(dotd(dir, dir)));
  double nearest = INFINITY;
  int nearestEdge = 0;
  for (int k = 0; k < 3; ++k) {
    const double dist = distanceToEdge(org, dUnit, v[k], v[(k + 1) % 3]);
    if (dist < nearest) {
      nearest = dist;
      nearestEdge = k;
    }
  }
  const bool nearEdge = nearest < std::fabs(margin);
  if (margin < 0.0) return nearEdge ? INFINITY : exact;
  if (exact != INFINITY || !nearEdge) return exact;
  // Grown and passing near an edge: the distance to the plane, or along the ray to the
  // edge's midpoint where the ray is parallel to the plane.
  const D3 n = crossd(v[1] - v[0], v[2] - v[0]);
  const double denom = dotd(n, dir);
  const D3 mid = (v[nearestEdge] + v[(nearestEdge + 1) % 3]) * 0.5;
  if (denom != 0.0) return dotd(n, v[0] - org) / denom;
  return dotd(mid - org, dir) / dotd(dir, dir);
}

BruteHits bruteForceBands(const Scene& scene, const double o[3], const double d[3], double tMin, double tMax) {
  BruteHits h;
  h.exact.t = h.grown.t = h.shrunk.t = tMax;
  auto consider = [&](BruteHit& best, double t, size_t tri) {
    if (t >= tMin && t < best.t) {
      best.t = t;
      best.triangle = long(tri);
    }
  };
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const double margin = floatEdgeMargin(scene, t, o);
    const double grown = rayTriangleWithMargin(scene, t, o, d, margin);
    if (grown == INFINITY) continue;  // outside the grown triangle: outside the others too
    consider(h.grown, grown, t);
    consider(h.exact, rayTriangle(scene, t, o, d), t);
    consider(h.shrunk, rayTriangleWithMargin(scene, t, o, d, -margin), t);
  }
  for (BruteHit* b : {&h.exact, &h.grown, &h.shrunk})
    if (b->triangle < 0) b->t = INFINITY;
  return h;
}

BruteHit bruteForceClosest(const Scene& scene, const double o[3], const double d[3], double tMin, double tMax) {
  BruteHit best;
  best.t = tMax;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const double dist = rayTriangle(scene, t, o, d);
    if (dist >= tMin && dist < best.t) {
      best.t = dist;
      best.triangle = long(t);
    }
  }
  if (best.triangle < 0) best.t = INFINITY;
  return best;
}

std::vector<float> exrChannels(const std::string& path, std::vector<std::string>* names) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error("cannot read " + path + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> values(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, values.data());
  if (names) *names = spec.channelnames;
  return values;
}

Film noisyFilm(int side, int passes, double sigma, double regionSigma, const std::function<bool(int, int)>& inRegion,
               unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Film film(side, side, false, true);
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<float> samples;
    for (int p = 0; p < side * side; ++p) {
      const double deviation = inRegion(p % side, p / side) ? regionSigma : sigma;
      for (int c = 0; c < 3; ++c) samples.push_back(float(0.5 + deviation * normal(rng)));
      samples.push_back(1.f);
    }
    film.addPass(samples);
  }
  return film;
}

std::vector<float> passWithFireflies(const Film& film, const std::vector<size_t>& pixels, float value) {
  std::vector<float> pass;
  for (size_t p = 0; p < film.pixels(); ++p) pass.insert(pass.end(), {0.5f, 0.5f, 0.5f, 1.f});
  for (size_t p : pixels) pass[4 * p] = pass[4 * p + 1] = pass[4 * p + 2] = value;
  return pass;
}

}  // namespace fh::test
