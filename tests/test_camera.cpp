// Camera conventions: pixel (0,0) is the top-left, right = forward x up, the vertical
// field of view is the camera's; camera files and flags are validated.
#include <gtest/gtest.h>

#include <cmath>

#include "base/error.h"
#include "base/vec.h"
#include "cli/flags.h"
#include "scene/camera.h"
#include "test_support.h"

namespace fh {
namespace {

TEST(Camera, TopLeftPixelLooksUpAndLeft) {
  Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fovYDeg = 90.f;
  const CameraFrame f = makeCameraFrame(c, 200, 100);
  EXPECT_NEAR(f.right[0], 1.f, 1e-6f);  // forward (-z) x up (+y) = +x
  const float3 d = cameraRayDirection(f, 0.f, 0.f, 200, 100);
  EXPECT_LT(d[0], 0.f);
  EXPECT_GT(d[1], 0.f);
  // The top edge is at tan(45 deg) = 1 up; the left edge at aspect (2) to the left.
  EXPECT_NEAR(d[1] / -d[2], 1.f, 1e-5f);
  EXPECT_NEAR(d[0] / -d[2], -2.f, 1e-5f);
  const float3 center = cameraRayDirection(f, 100.f, 50.f, 200, 100);
  EXPECT_NEAR(center[0], 0.f, 1e-6f);
  EXPECT_NEAR(center[1], 0.f, 1e-6f);
}

TEST(Camera, JsonSidecarFormat) {
  const std::string dir = test::tempDir("camera");
  test::writeFile(dir + "/c.json", R"({"eye": [0, 1, 3.9], "target": [0, 1, 0], "up": [0, 1, 0], "fov_y_deg": 39.3})");
  const Camera c = loadCameraJson(dir + "/c.json");
  EXPECT_FLOAT_EQ(c.eye[2], 3.9f);
  EXPECT_FLOAT_EQ(c.fovYDeg, 39.3f);
}

TEST(Camera, BadCameraFilesNameTheProblem) {
  const std::string dir = test::tempDir("camera");
  auto message = [&](const std::string& json) {
    test::writeFile(dir + "/bad.json", json);
    try {
      loadCameraJson(dir + "/bad.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("{").find("invalid JSON"), std::string::npos);
  // Found by fuzzing: a number beyond a double threw nlohmann's out_of_range, not an Error.
  EXPECT_NE(message(R"({"eye": [1e3830,0,0], "target": [0,0,0], "fov_y_deg": 40})").find("invalid JSON"),
            std::string::npos);
  EXPECT_NE(message(R"({"target": [0,0,0], "fov_y_deg": 40})").find("missing \"eye\""), std::string::npos);
  EXPECT_NE(message(R"({"eye": [0,0,1], "target": [0,0,0], "fov_y_deg": 200})").find("(0, 180)"),
            std::string::npos);
  EXPECT_NE(message(R"({"eye": [0,0,0], "target": [0,0,0], "fov_y_deg": 40})").find("coincide"), std::string::npos);
  EXPECT_NE(message(R"({"eye": [0,1,0], "target": [0,0,0], "up": [0,1,0], "fov_y_deg": 40})").find("parallel"),
            std::string::npos);
  EXPECT_NE(message(R"({"eye": [0,0,1], "target": [0,0,0], "up": [0,0,0], "fov_y_deg": 40})").find("zero"),
            std::string::npos);
  // A camera is valid in any units: far apart (their difference's square overflows a float),
  // close together (it underflows), far from the origin but close together.
  EXPECT_EQ(message(R"({"eye": [1e38,0,3], "target": [-1e38,0,0], "fov_y_deg": 40})"), "");
  EXPECT_EQ(message(R"({"eye": [1e20,0,0], "target": [0,0,0], "up": [0,1e30,0], "fov_y_deg": 40})"), "");
  EXPECT_EQ(message(R"({"eye": [1e-30,0,0], "target": [0,0,0], "up": [0,1e-30,0], "fov_y_deg": 40})"), "");
  EXPECT_EQ(message(R"({"eye": [1e30,0,1], "target": [1e30,0,0], "fov_y_deg": 40})"), "");
  EXPECT_THROW(loadCameraJson(dir + "/missing.json"), Error);
}

TEST(Camera, VectorFlags) {
  EXPECT_EQ(parseVec3Flag("--eye", "0,1,3.5"), (float3{0.f, 1.f, 3.5f}));
  EXPECT_THROW(parseVec3Flag("--eye", "0,1"), Error);
  EXPECT_THROW(parseVec3Flag("--eye", "0,1,2,3"), Error);
  EXPECT_THROW(parseVec3Flag("--eye", "0,x,2"), Error);
  EXPECT_THROW(parseVec3Flag("--eye", "0,nan,2"), Error);
}

// The basis is computed at a unit scale: the same bits for a camera in any units, and for
// an up vector of any length.
TEST(Camera, TheFrameIsTheSameInAnyUnits) {
  Camera c;
  c.eye = {0.3f, 1.1f, 3.7f};
  c.target = {-0.2f, 0.9f, 0.1f};
  c.up = {0.1f, 1.f, 0.f};
  const CameraFrame unit = makeCameraFrame(c, 16, 9);
  for (int exponent : {-120, -40, -1, 3, 40, 120}) {
    Camera scaled = scaledCamera(c, std::ldexp(1.f, exponent));
    scaled.up = c.up * std::ldexp(1.f, -exponent);
    const CameraFrame f = makeCameraFrame(scaled, 16, 9);
    EXPECT_EQ(f.forward, unit.forward) << exponent;
    EXPECT_EQ(f.right, unit.right) << exponent;
    EXPECT_EQ(f.up, unit.up) << exponent;
    EXPECT_EQ(f.origin, c.eye * std::ldexp(1.f, exponent)) << exponent;
    EXPECT_NO_THROW(validateCamera(scaled, "camera")) << exponent;
  }
}

TEST(Camera, FramingSeesTheWholeBox) {
  const Camera c = frameBounds({-1, -2, -3}, {1, 2, 3}, 40.f);
  const float3 toCorner = float3{1, 2, 3} - c.eye;
  const float3 forward = normalize(c.target - c.eye);
  const float angle = std::acos(dot(normalize(toCorner), forward)) * 180.f / float(M_PI);
  EXPECT_LT(angle, 20.f);
}

}  // namespace
}  // namespace fh
