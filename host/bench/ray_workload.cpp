// Ray batches made on the device: generate, spawn_bounce_rays, spawn_shadow_rays.
#include "bench/ray_workload.h"

#include "scene/camera.h"

namespace fh {

ProgramSpec benchRaysProgram(const std::string& traversalOptions) {
  return {"bench rays", {"camera_rays.cl", "bench_rays.cl"}, traversalOptions};
}

RayWorkload::RayWorkload(DeviceContext& dc, const Scene& scene, const Bvh& bvh, RayCaster& caster)
    : dc_(dc), caster_(caster) {
  const cl::Program program = buildProgram(dc.context, dc.info.device, benchRaysProgram(caster.traversalOptions()));
  generate_ = createKernel(program, "generate_camera_rays");
  bounce_ = createKernel(program, "spawn_bounce_rays");
  shadow_ = createKernel(program, "spawn_shadow_rays");

  // Light triangles in BVH order.
  std::vector<int> bvhIndexOf(bvh.order.size());
  for (size_t k = 0; k < bvh.order.size(); ++k) bvhIndexOf[bvh.order[k]] = int(k);
  std::vector<int> lights;
  for (const Light& l : scene.lights) lights.push_back(bvhIndexOf[l.triangle]);
  lightCount_ = unsigned(lights.size());
  lights_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, lights.size() * sizeof(int), "light list",
                           lights.empty() ? nullptr : lights.data());
  counter_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, sizeof(unsigned), "queue counter");
}

RayQueue RayWorkload::allocate(unsigned capacity) {
  RayQueue q;
  q.org = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_WRITE, capacity * 16ull, "ray origins");
  q.dir = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_WRITE, capacity * 16ull, "ray directions");
  q.source = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_WRITE, capacity * 4ull, "ray sources");
  return q;
}

unsigned RayWorkload::readCount() {
  unsigned n = 0;
  FH_CL(dc_.queue.enqueueReadBuffer(counter_, CL_TRUE, 0, sizeof n, &n));
  return n;
}

RayQueue RayWorkload::primary(const Camera& camera, int width, int height, unsigned seed) {
  const unsigned n = unsigned(width) * unsigned(height);
  RayQueue q = allocate(n);
  const gpu::CameraParams cam = makeCameraParams(camera, width, height);
  setKernelArgs(generate_, cam, seed, 0u, 0u, q.org, q.dir, q.source, n);
  launch(dc_, generate_, n, "generate_camera_rays");
  q.count = n;
  return q;
}

cl::Buffer RayWorkload::closestHits(const RayQueue& rays, RayOrder order) {
  cl::Buffer hits = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_WRITE, rays.count * 16ull, "hits");
  caster_.intersectClosest(rays.org, rays.dir, hits, rays.count, order);
  return hits;
}

RayQueue RayWorkload::bounce(const RayQueue& from, const cl::Buffer& hits, unsigned seed) {
  RayQueue q = allocate(from.count);
  FH_CL(dc_.queue.enqueueFillBuffer(counter_, 0u, 0, sizeof(unsigned)));
  setKernelArgs(bounce_, hits, from.dir, caster_.triangles(), seed, q.org, q.dir, q.source, counter_, from.count);
  launch(dc_, bounce_, from.count, "spawn_bounce_rays");
  q.count = readCount();
  return q;
}

RayQueue RayWorkload::shadow(const RayQueue& from, const cl::Buffer& hits, unsigned seed) {
  RayQueue q = allocate(from.count);
  if (lightCount_ == 0) return q;
  FH_CL(dc_.queue.enqueueFillBuffer(counter_, 0u, 0, sizeof(unsigned)));
  setKernelArgs(shadow_, hits, from.dir, caster_.triangles(), lights_, lightCount_, seed, q.org, q.dir, q.source,
                counter_, from.count);
  launch(dc_, shadow_, from.count, "spawn_shadow_rays");
  q.count = readCount();
  return q;
}

std::vector<float> RayWorkload::readFloat4(const cl::Buffer& buffer, unsigned count) const {
  std::vector<float> out(size_t(count) * 4);
  if (count) FH_CL(dc_.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, out.size() * 4, out.data()));
  return out;
}

std::vector<unsigned> RayWorkload::readUints(const cl::Buffer& buffer, unsigned count) const {
  std::vector<unsigned> out(count);
  if (count) FH_CL(dc_.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, out.size() * 4, out.data()));
  return out;
}

RayQueue RayWorkload::upload(const std::vector<float>& org, const std::vector<float>& dir) {
  RayQueue q = allocate(unsigned(org.size() / 4));
  q.count = unsigned(org.size() / 4);
  if (q.count) {
    FH_CL(dc_.queue.enqueueWriteBuffer(q.org, CL_TRUE, 0, org.size() * 4, org.data()));
    FH_CL(dc_.queue.enqueueWriteBuffer(q.dir, CL_TRUE, 0, dir.size() * 4, dir.data()));
  }
  return q;
}

}  // namespace fh
