// Light tracing (--method lt, kernels/light_trace.cl) and bidirectional path tracing
// (--method bdpt, kernels/bdpt.cl) on one device: a pass is one light path per pixel of the
// image (and for bdpt one camera path per pixel too), each connected to the camera at every
// vertex that can be, its contributions splatted to the pixels they land on as whole film
// quanta in 64-bit integers. A pass's sums are then the same bits whichever order its paths
// added them in, so films merge exactly as the path tracer's do. A pass runs as launches
// into a splat buffer of its own (bdpt: as many paths a launch as its light vertices' buffer
// holds), read back whole.
//
// Light paths cannot reach the camera through a delta lobe (a mirror or glass seen
// directly): for lt, in a scene that has them, a camera pass (the path tracer's mis, keeping
// only the paths that leave their first vertex by a delta lobe: FH_LIGHT_TRACED_FIRST_VERTEX)
// renders the same pass beside it, and a pass's sample is the sum of the two. bdpt's camera
// subpaths find those paths themselves.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "render/device_scene.h"
#include "render/merge_grid.h"
#include "render/pass_renderer.h"
#include "render/wavefront.h"
#include "scene/camera.h"

namespace fh {

// The light tracer's (method lt) or bidirectional path tracer's (bdpt) program for a scene's
// features: `lanes` paths per work-item (kernels/lanes.h: 1, or 8 for a CPU), light paths
// for lt, a light and a camera subpath each for bdpt and vcm.
ProgramSpec lightTracerProgram(Method method, const SceneFeatures& features, const std::string& traversalOptions,
                               unsigned lanes);

// Whether vcm merges light vertices in a scene with (or without) delta lobes
// (render/device_scene.h hasDeltaLobes): only a delta lobe (glass, a mirror) can make
// merging a strategy (kernels/bdpt.cl merging_possible). Without one, vcm renders bdpt's
// paths with bdpt's weights, in bdpt's program. vcm's own program (FH_VCM) is
// lightTracerProgram(Method::VCM, ...).
bool mergesLightVertices(Method method, bool deltaLobes);

class LightTracer : public PassRenderer {
 public:
  LightTracer(DeviceContext& dc, const PreparedScene& scene, const Bvh& bvh, const Camera& camera,
              const RenderSettings& s);

  bool fits(const std::shared_ptr<const RoundPixels>& pixels, uint64_t granted, uint64_t returned) const override;
  void grantPass(uint64_t local, uint32_t global, std::shared_ptr<const RoundPixels> pixels) override;
  void startGrantedPasses() override;
  uint32_t globalPass(uint64_t local) const override { return slots_[local % kSlots].global; }

  void enqueueIteration() override;
  void readCounters() override;
  bool passComplete(uint64_t local) const override;
  void takePass(uint64_t local, std::vector<float>& samples) override;

  RenderStats stats() override;
  size_t wavefront() const override { return pixels_; }
  Strategy strategy() const override { return Strategy::Scalar; }

 private:
  // Passes in flight: each holds a splat buffer of 24 bytes a pixel.
  static constexpr size_t kSlots = 2;
  enum class State { Free, Granted, Launched, Read };
  struct Slot {
    uint32_t global = 0;
    State state = State::Free;
    cl::Buffer splats, tallies;
    std::vector<uint32_t> splatWords;  // read back here
    std::array<uint32_t, 3> tallyWords{};
  };

  DeviceContext& dc_;
  // The paths seen through a delta lobe first, where the scene has such lobes; else null.
  std::unique_ptr<WavefrontPipeline> cameraPaths_;
  // The scene on the device, uploaded once: the camera paths' where there are any.
  std::unique_ptr<DeviceScene> ownScene_;
  const DeviceScene& scene_;
  gpu::RenderParams params_{};
  unsigned pixels_;
  Method method_;
  bool merges_;  // mergesLightVertices
  const char* kernelName_;
  unsigned lanes_;  // light paths a work-item
  cl::Kernel kernel_;
  cl::Buffer density_;
  // bdpt: the filter's inverse CDF (camera paths) and the light vertices of one launch's paths.
  cl::Buffer filterTable_, lightVertices_;
  unsigned pathsPerLaunch_ = 0;
  // vcm: the light subpaths' kernel (kernel_ runs the camera subpaths), each launch's
  // vertices per path, read back with the vertices themselves, and their merging grid.
  cl::Kernel lightKernel_, gatherKernel_;
  cl::Buffer storedCounts_, offsetsBuffer_, positions_, gridStarts_, gridFiled_;
  std::vector<uint32_t> counts_, offsets_;
  std::vector<float> positionWords_;
  MergeGrid grid_;
  float firstMergeRadius_ = 0;
  unsigned maxDepth_ = 0;
  // bdpt: the scene's bounding sphere (centre, radius), where light subpaths from the
  // environment map start.
  cl_float4 sphere_{};
  std::array<Slot, kSlots> slots_;
  void mergeLaunch(Slot& slot, unsigned first);
  uint64_t nextLaunch_ = 0, granted_ = 0;  // local passes
  RenderStats stats_;
  double kernelSeconds_ = 0;
  std::vector<std::pair<const char*, cl::Event>> events_;  // each launch's kernel and event
};

}  // namespace fh
