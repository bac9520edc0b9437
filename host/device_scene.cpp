// Uploading a scene: materials, light tables, BVH.
#include "device_scene.h"

#include <cstring>

namespace fh {
namespace {

float luminance(const Vec3f& c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

template <typename T>
cl::Buffer upload(DeviceContext& dc, const std::vector<T>& data, const char* what) {
  return allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, data.size() * sizeof(T), what,
                        data.empty() ? nullptr : data.data());
}

}  // namespace

LightTable buildLightTable(const Scene& scene, const Bvh& bvh) {
  std::vector<int> bvhIndexOf(bvh.order.size());
  for (size_t k = 0; k < bvh.order.size(); ++k) bvhIndexOf[bvh.order[k]] = int(k);
  LightTable table;
  table.pdfArea.assign(scene.triangleCount(), 0.f);
  double total = 0.0;
  std::vector<double> power;
  for (const Light& l : scene.lights) {
    const double p = luminance(l.power);
    if (!(p > 0.0)) continue;
    power.push_back(p);
    table.triangle.push_back(bvhIndexOf[l.triangle]);
    total += p;
  }
  double running = 0.0;
  size_t i = 0;
  for (const Light& l : scene.lights) {
    if (!(luminance(l.power) > 0.f)) continue;
    running += power[i];
    table.cdf.push_back(float(running / total));
    table.pdfArea[size_t(table.triangle[i])] = float(power[i] / total / l.area);
    ++i;
  }
  if (!table.cdf.empty()) table.cdf.back() = 1.f;  // no rounding gap at the top
  return table;
}

std::vector<gpu::GpuMaterial> toGpuMaterials(const Scene& scene) {
  std::vector<gpu::GpuMaterial> out(scene.materials.size());
  for (size_t i = 0; i < out.size(); ++i) {
    const Material& m = scene.materials[i];
    gpu::GpuMaterial& g = out[i];
    std::memset(&g, 0, sizeof g);
    for (size_t c = 0; c < 3; ++c) {
      g.kd[c] = m.kd[c];
      g.ke[c] = m.ke[c];
      g.ks[c] = m.ks[c];
      g.tf[c] = m.tf[c];
    }
    g.ks[3] = m.ns;
    g.tf[3] = m.ni;
    g.illum = m.illum;
    g.texture = m.kdTexture;
  }
  return out;
}

DeviceScene::DeviceScene(DeviceContext& dc, const Scene& scene, const Bvh& bvh) : caster(dc, bvh) {
  const LightTable lights = buildLightTable(scene, bvh);
  lightCount = unsigned(lights.cdf.size());
  triangleMaterial = upload(dc, toBvhOrder(scene.triangleMaterial, bvh.order), "triangle materials");
  materials = upload(dc, toGpuMaterials(scene), "materials");
  lightCdf = upload(dc, lights.cdf, "light CDF");
  lightTriangle = upload(dc, lights.triangle, "light triangles");
  lightPdfArea = upload(dc, lights.pdfArea, "light densities");
}

}  // namespace fh
