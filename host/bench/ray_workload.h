// Batches of rays for measuring and testing the ray-casting operation: camera rays, then
// from their hits cosine-weighted bounce rays and shadow rays to the emitters, all made
// on the device with the same kernels and offsets the path tracer uses.
#pragma once
#include <vector>

#include "accel/ray_caster.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

struct RayQueue {
  cl::Buffer org, dir;  // float4 each: origin.xyz + tmin, direction.xyz + tmax
  cl::Buffer source;    // for spawned rays: the index of the hit each came from
  unsigned count = 0;
};

// The kernels that make those batches.
ProgramSpec benchRaysProgram(const std::string& traversalOptions);

class RayWorkload {
 public:
  RayWorkload(DeviceContext& dc, const Scene& scene, const Bvh& bvh, RayCaster& caster);

  RayQueue primary(const Camera& camera, int width, int height, unsigned seed);
  cl::Buffer closestHits(const RayQueue& rays, RayOrder order = RayOrder::Incoherent);
  RayQueue bounce(const RayQueue& from, const cl::Buffer& hits, unsigned seed);
  // Shadow rays to uniform points on the scene's emitters; an empty queue without any.
  RayQueue shadow(const RayQueue& from, const cl::Buffer& hits, unsigned seed);

  std::vector<float> readFloat4(const cl::Buffer& buffer, unsigned count) const;
  std::vector<unsigned> readUints(const cl::Buffer& buffer, unsigned count) const;
  RayQueue upload(const std::vector<float>& org, const std::vector<float>& dir);

 private:
  RayQueue allocate(unsigned capacity);
  unsigned readCount();

  DeviceContext& dc_;
  RayCaster& caster_;
  cl::Kernel generate_, bounce_, shadow_;
  cl::Buffer lights_, counter_;
  unsigned lightCount_ = 0;
};

}  // namespace fh
