// Camera sources and the camera basis.
#include "scene/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/input_file.h"
#include "base/vec.h"

namespace fh {
namespace {

// A JSON number as a float; beyond float's range is an error (the cast would be undefined).
float toFloat(const nlohmann::json& number, const std::string& path, const std::string& key) {
  const double v = number.get<double>();
  if (!(std::fabs(v) <= double(std::numeric_limits<float>::max())))
    throw Error(path + ": camera \"" + key + "\" holds a number beyond single precision");
  return float(v);
}

std::array<float, 3> readVec3(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j.contains(key)) throw Error(path + ": camera is missing \"" + key + "\"");
  const auto& v = j.at(key);
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw Error(path + ": camera \"" + key + "\" must be an array of three numbers");
  std::array<float, 3> out{};
  for (size_t k = 0; k < 3; ++k) out[k] = toFloat(v[k], path, key);
  return out;
}

// (x, y, z) scaled by the power of two (exact) that brings its largest component into
// [1, 2): a vector whose square neither over- nor underflows, whatever the scene's units.
float3 atUnitScale(double x, double y, double z) {
  const double largest = std::max({std::fabs(x), std::fabs(y), std::fabs(z)});
  const int e = largest > 0.0 ? -std::ilogb(largest) : 0;
  return {float(std::ldexp(x, e)), float(std::ldexp(y, e)), float(std::ldexp(z, e))};
}

}  // namespace

Camera loadCameraJson(const std::string& path, const std::string& what) {
  return parseCameraJson(readInputFile(path, what, kMaxCameraBytes), path);
}

Camera parseCameraJson(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // a syntax error, or a number that overflows a double
    throw Error(path + ": invalid JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw Error(path + ": camera file must hold a JSON object");
  Camera c;
  c.eye = readVec3(j, "eye", path);
  c.target = readVec3(j, "target", path);
  c.up = j.contains("up") ? readVec3(j, "up", path) : std::array<float, 3>{0.f, 1.f, 0.f};
  if (!j.contains("fov_y_deg") || !j["fov_y_deg"].is_number())
    throw Error(path + ": camera needs a number \"fov_y_deg\"");
  c.fovYDeg = toFloat(j["fov_y_deg"], path, "fov_y_deg");
  validateCamera(c, path);
  return c;
}

void validateCamera(const Camera& c, const std::string& source) {
  if (!isFinite(c.eye) || !isFinite(c.target) || !isFinite(c.up) || !std::isfinite(c.fovYDeg))
    throw Error(source + ": camera values must be finite");
  if (!(c.fovYDeg > 0.f && c.fovYDeg < 180.f))
    throw Error(source + ": vertical field of view must lie in (0, 180) degrees");
  // In double: in float, (target - eye) or its squared length may underflow.
  double distance2 = 0.0;
  for (size_t k = 0; k < 3; ++k) distance2 += std::pow(double(c.target[k]) - double(c.eye[k]), 2);
  if (distance2 == 0.0) throw Error(source + ": camera eye and target coincide");
  const CameraFrame frame = makeCameraFrame(c, 1, 1);
  if (!isFinite(frame.right) || length(cross(frame.forward, atUnitScale(c.up[0], c.up[1], c.up[2]))) < 1e-6f)
    throw Error(source + ": camera up vector is zero or parallel to the view direction");
}

Camera frameBounds(const std::array<float, 3>& lo, const std::array<float, 3>& hi, float fovYDeg) {
  const float3 center = (lo + hi) * 0.5f;
  const float radius = std::fmax(0.5f * length(hi - lo), 1e-6f);
  const float distance = radius / std::sin(0.5f * fovYDeg * float(M_PI) / 180.f);
  Camera c;
  c.target = center;
  c.eye = center + float3{0.f, 0.f, distance};
  c.up = {0.f, 1.f, 0.f};
  c.fovYDeg = fovYDeg;
  return c;
}

Camera scaledCamera(Camera camera, float scale) {
  for (size_t k = 0; k < 3; ++k) {
    camera.eye[k] *= scale;
    camera.target[k] *= scale;
  }
  return camera;
}

CameraFrame makeCameraFrame(const Camera& c, int width, int height) {
  CameraFrame f;
  f.origin = c.eye;
  f.forward = normalize(
      atUnitScale(double(c.target[0]) - c.eye[0], double(c.target[1]) - c.eye[1], double(c.target[2]) - c.eye[2]));
  f.right = normalize(cross(f.forward, atUnitScale(c.up[0], c.up[1], c.up[2])));
  f.up = cross(f.right, f.forward);
  f.tanHalfFovY = std::tan(0.5f * c.fovYDeg * float(M_PI) / 180.f);
  f.aspect = float(width) / float(height);
  return f;
}

std::array<float, 3> cameraRayDirection(const CameraFrame& f, float px, float py, int width, int height) {
  const float sx = (2.f * px / float(width) - 1.f) * f.tanHalfFovY * f.aspect;
  const float sy = (1.f - 2.f * py / float(height)) * f.tanHalfFovY;
  return f.forward + f.right * sx + f.up * sy;
}

gpu::CameraParams makeCameraParams(const Camera& camera, int width, int height) {
  const CameraFrame f = makeCameraFrame(camera, width, height);
  gpu::CameraParams p{};
  for (int k = 0; k < 3; ++k) {
    p.origin[k] = f.origin[size_t(k)];
    p.forward[k] = f.forward[size_t(k)];
    p.right[k] = f.right[size_t(k)] * f.tanHalfFovY * f.aspect;
    p.up[k] = f.up[size_t(k)] * f.tanHalfFovY;
  }
  p.width = width;
  p.height = height;
  return p;
}

}  // namespace fh
