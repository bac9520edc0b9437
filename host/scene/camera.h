// The pinhole camera: where it comes from (--camera JSON, --eye/--target/--up/--fov
// flags, a SCENE.camera.json sidecar, or framing the scene's bounds) and its basis.
// Pixel (0,0) is the top-left of the image; the right vector is forward x up.
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "kernels/types.h"

namespace fh {

struct Camera {
  std::array<float, 3> eye{0.f, 1.f, 3.9f};
  std::array<float, 3> target{0.f, 1.f, 0.f};
  std::array<float, 3> up{0.f, 1.f, 0.f};
  float fovYDeg = 39.3f;
};

// The orthonormal basis and image-plane extents the generate kernel uses.
struct CameraFrame {
  std::array<float, 3> origin, forward, right, up;
  float tanHalfFovY = 0.f, aspect = 1.f;
};

// The most a camera file may hold: a few numbers, with room for whitespace and comments.
constexpr uint64_t kMaxCameraBytes = uint64_t(1) << 20;

// Reads {"eye","target","up","fov_y_deg"} through the input gate (base/input_file.h: a
// regular file of at most kMaxCameraBytes); errors name the file (as `what`, its role:
// "--camera", or "camera" for a scene's .camera.json) and the bad key.
Camera loadCameraJson(const std::string& path, const std::string& what = "--camera");
Camera parseCameraJson(const std::string& text, const std::string& name);

// Parses "x,y,z" given to `flag`; errors name the flag.

// Throws fh::Error (naming `source`) if eye == target, up is zero or parallel to the view
// direction, a value is not finite or the fov is outside (0, 180).
void validateCamera(const Camera& camera, const std::string& source);

// A camera that looks at the box [lo, hi] from +Z, framing it whole.
Camera frameBounds(const std::array<float, 3>& lo, const std::array<float, 3>& hi, float fovYDeg = 40.f);

// The camera with its eye and target scaled by `scale` (Scene::worldScale: from the
// scene file's units to the renderer's); the view is the same.
Camera scaledCamera(Camera camera, float scale);

CameraFrame makeCameraFrame(const Camera& camera, int width, int height);

// The same frame as the kernels take it (kernels/camera.h), right and up scaled by the
// field of view.
gpu::CameraParams makeCameraParams(const Camera& camera, int width, int height);

// The direction (unnormalized) through image position (px, py) in pixels, (0,0) top-left.
std::array<float, 3> cameraRayDirection(const CameraFrame& frame, float px, float py, int width, int height);

}  // namespace fh
