// Test helpers.
#include "test_support.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

namespace fh::test {
namespace fs = std::filesystem;

bool haveSharedScenes() { return fs::is_directory(FREDHOLM_SHARED_SCENES); }

std::string sharedScene(const std::string& relative) {
  return haveSharedScenes() ? std::string(FREDHOLM_SHARED_SCENES) + "/" + relative : "";
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

CommandResult runFredholm(const std::string& args, const std::string& env) {
  const std::string command = env + " " + FREDHOLM_BINARY + " " + args + " 2>&1";
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

BruteHit bruteForceClosest(const Scene& scene, const double o[3], const double d[3], double tMin, double tMax) {
  BruteHit best;
  best.t = tMax;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    double v[3][3];
    for (int k = 0; k < 3; ++k) {
      const Vec3f p = scene.corner(t, k);
      for (int j = 0; j < 3; ++j) v[k][j] = p[size_t(j)];
    }
    const double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
    const double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
    const double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0.0) continue;
    const double inv = 1.0 / det;
    const double s[3] = {o[0] - v[0][0], o[1] - v[0][1], o[2] - v[0][2]};
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    const double w = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (w < 0.0 || u + w > 1.0) continue;
    const double dist = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    if (dist >= tMin && dist < best.t) {
      best.t = dist;
      best.triangle = long(t);
    }
  }
  if (best.triangle < 0) best.t = INFINITY;
  return best;
}

}  // namespace fh::test
