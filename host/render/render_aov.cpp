// The AOV pipeline: generate -> intersect -> shade_aov, one pass per sample.
#include "render/render_aov.h"

#include <algorithm>

namespace fh {

ProgramSpec aovProgram() { return {"aov", {"camera_rays.cl", "aov.cl"}, ""}; }

Image renderAov(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera, const AovSettings& s) {
  RayCaster caster(dc, bvh);
  const cl::Program program = buildProgram(dc.context, dc.info.device, aovProgram());
  cl::Kernel generate = createKernel(program, "generate_camera_rays");
  cl::Kernel shade = createKernel(program, "shade_aov");

  const unsigned pixels = unsigned(s.width) * unsigned(s.height);
  const auto& device = dc.info.device;
  auto buffer = [&](size_t bytes, const char* what, const void* host = nullptr) {
    return allocateBuffer(dc.context, device, host ? CL_MEM_READ_ONLY : CL_MEM_READ_WRITE, bytes, what, host);
  };
  cl::Buffer org = buffer(pixels * 16ull, "ray origins"), dir = buffer(pixels * 16ull, "ray directions");
  cl::Buffer rayPixel = buffer(pixels * 4ull, "ray pixels"), hits = buffer(pixels * 16ull, "hits");
  cl::Buffer film = buffer(pixels * 16ull, "film");
  FH_CL(dc.queue.enqueueFillBuffer(film, 0.f, 0, pixels * 16ull));

  const std::vector<int> triangleMaterial = toBvhOrder(scene.triangleMaterial, bvh.order);
  std::vector<float> albedo;
  for (const auto& m : scene.materials) albedo.insert(albedo.end(), {m.kd[0], m.kd[1], m.kd[2], 1.f});
  cl::Buffer materialOf = buffer(triangleMaterial.size() * 4, "triangle materials", triangleMaterial.data());
  cl::Buffer materialAlbedo = buffer(albedo.size() * 4, "material albedo", albedo.data());

  const gpu::CameraParams cam = makeCameraParams(camera, s.width, s.height);
  for (int sample = 0; sample < std::max(1, s.spp); ++sample) {
    setKernelArgs(generate, cam, s.seed, unsigned(sample), 0u, org, dir, rayPixel, pixels);
    launch(dc, generate, pixels, "generate_camera_rays");
    caster.intersectClosest(org, dir, hits, pixels, RayOrder::Coherent);
    setKernelArgs(shade, int(s.mode), hits, rayPixel, caster.triangles(), materialOf, materialAlbedo, film, pixels);
    launch(dc, shade, pixels, "shade_aov");
  }
  std::vector<float> sums(size_t(pixels) * 4);
  FH_CL(dc.queue.enqueueReadBuffer(film, CL_TRUE, 0, sums.size() * 4, sums.data()));

  Image image;
  image.width = s.width;
  image.height = s.height;
  image.rgb.resize(size_t(pixels) * 3);
  const float unit = s.mode == Aov::Depth ? 1.f / scene.worldScale : 1.f;  // depth in the file's units
  for (size_t p = 0; p < pixels; ++p)
    for (size_t c = 0; c < 3; ++c)
      image.rgb[3 * p + c] = sums[4 * p + 3] > 0.f ? sums[4 * p + c] / sums[4 * p + 3] * unit : 0.f;
  return image;
}

}  // namespace fh
