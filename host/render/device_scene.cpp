// Uploading a scene: materials, light tables, BVH.
#include "render/device_scene.h"

#ifdef FREDHOLM_HAVE_OIIO
#include <OpenImageIO/imageio.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "base/vec.h"
#include "image/image_io.h"

namespace fh {
namespace {

float luminance(const Vec3f& c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

template <typename T>
cl::Buffer upload(DeviceContext& dc, const std::vector<T>& data, const char* what) {
  return allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, data.size() * sizeof(T), what,
                        data.empty() ? nullptr : data.data());
}

}  // namespace

LightTable buildLightTable(const Scene& scene, const Bvh& bvh, const EnvironmentMap* environment) {
  std::vector<int> bvhIndexOf(bvh.order.size());
  for (size_t k = 0; k < bvh.order.size(); ++k) bvhIndexOf[bvh.order[k]] = int(k);
  LightTable table;
  table.pdfArea.assign(scene.triangleCount(), 0.f);
  Vec3f lo, hi;
  scene.bounds(lo, hi);
  const double radius = lo[0] <= hi[0] ? 0.5 * std::sqrt(double(dot(hi - lo, hi - lo))) : 0.0;
  if (lo[0] <= hi[0])
    table.boundingSphere = {0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2]), float(radius)};
  double environmentPower = 0.0;
  if (environment && environment->luminanceIntegral > 0.0) {
    environmentPower = 3.14159265358979323846 * radius * radius * environment->luminanceIntegral;
    // A scene of one point (or none) still receives the map's light.
    if (!(environmentPower > 0.0) || !std::isfinite(environmentPower)) environmentPower = 1.0;
  }
  double total = environmentPower;
  std::vector<double> power;
  for (const Light& l : scene.lights) {
    const double p = luminance(l.power);
    if (!(p > 0.0)) continue;
    power.push_back(p);
    table.triangle.push_back(bvhIndexOf[l.triangle]);
    total += p;
  }
  table.environmentPick = total > 0.0 ? float(environmentPower / total) : 0.f;
  // Among the triangles, half the picks go by power and half uniformly (a defensive
  // mixture, Hesterberg 1995): by power alone, a few small lights beside a bright one are
  // almost never picked, and the surfaces that mirror them are lit by BSDF samples alone,
  // with fireflies; the mixture costs power sampling at most twice its variance.
  const double trianglePower = total - environmentPower, trianglesPick = 1.0 - double(table.environmentPick);
  double running = double(table.environmentPick);
  size_t i = 0;
  for (const Light& l : scene.lights) {
    if (!(luminance(l.power) > 0.f)) continue;
    const double pick = trianglesPick * (0.5 * power[i] / trianglePower + 0.5 / double(power.size()));
    running += pick;
    table.cdf.push_back(float(running));
    table.pdfArea[size_t(table.triangle[i])] = float(pick / l.area);
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

std::string SceneFeatures::buildOptions() const {
  std::string o;
  if (glossy) o += " -DFH_GLOSSY";
  if (glass) o += " -DFH_GLASS";
  if (textures) o += " -DFH_TEXTURES";
  if (shadingNormals) o += " -DFH_SHADING_NORMALS";
  if (environmentMap) o += " -DFH_ENV_MAP";
  return o;
}

std::string SceneFeatures::describe() const {
  std::string d;
  for (const auto& [on, name] : {std::pair{glossy, "glossy"}, {glass, "glass"}, {textures, "textures"},
                                 {shadingNormals, "shading normals"}, {environmentMap, "environment map"}})
    if (on) d += std::string(d.empty() ? "" : ", ") + name;
  return d.empty() ? "diffuse only" : d;
}

SceneFeatures sceneFeatures(const Scene& scene) {
  std::set<int> used(scene.triangleMaterial.begin(), scene.triangleMaterial.end());
  SceneFeatures f;
  for (int id : used) {
    const Material& m = scene.materials[size_t(id)];
    const bool specular = m.ks[0] > 0.f || m.ks[1] > 0.f || m.ks[2] > 0.f;
    if (m.isGlass()) f.glass = true;
    else if (specular && m.illum >= 2) f.glossy = true;
    if (m.kdTexture >= 0 && !scene.cornerUVs.empty()) f.textures = true;
  }
  f.shadingNormals = !scene.cornerNormals.empty();
  return f;
}

bool hasDeltaLobes(const Scene& scene) {
  for (int id : std::set<int>(scene.triangleMaterial.begin(), scene.triangleMaterial.end())) {
    const Material& m = scene.materials[size_t(id)];
    const bool specular = m.ks[0] > 0.f || m.ks[1] > 0.f || m.ks[2] > 0.f;
    const bool mirror = (m.illum == 3 || m.illum == 5 || m.illum == 8) && specular && m.ns >= FH_NS_MIRROR;
    if (m.isGlass() || mirror) return true;
  }
  return false;
}

namespace {

uint32_t floatBits(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

}  // namespace

std::vector<uint32_t> srgbDecodeTable() {
  float encoded[256];
#ifdef FREDHOLM_HAVE_OIIO
  // Converted by OpenImageIO as it converts an 8-bit image read as float, so a texel
  // decodes to the bits it had when textures were stored as floats.
  unsigned char codes[256];
  for (int c = 0; c < 256; ++c) codes[c] = static_cast<unsigned char>(c);
  OIIO::convert_pixel_values(OIIO::TypeDesc::UINT8, codes, OIIO::TypeDesc::FLOAT, encoded, 256);
#else
  for (int c = 0; c < 256; ++c) encoded[c] = float(c) / 255.f;
#endif
  std::vector<uint32_t> table(256);
  for (int c = 0; c < 256; ++c) table[size_t(c)] = floatBits(srgbToLinear(encoded[c]));
  return table;
}

namespace {

// A float texel as a reflectance, counted in t where it was not one (TextureData).
void mendReflectance(float rgb[3], TextureData& t) {
  if (!std::isfinite(rgb[0]) || !std::isfinite(rgb[1]) || !std::isfinite(rgb[2])) {
    rgb[0] = rgb[1] = rgb[2] = 0.5f;
    ++t.notFinite;
    return;
  }
  if (rgb[0] < 0.f || rgb[1] < 0.f || rgb[2] < 0.f) {
    for (int c = 0; c < 3; ++c) rgb[c] = std::max(rgb[c], 0.f);
    ++t.negative;
  }
  if (capReflectance(rgb)) ++t.aboveOne;
}

// What loadTexture mended, for a warning; empty if nothing.
std::string mended(const TextureData& t) {
  std::string out;
  const std::pair<size_t, const char*> kinds[] = {{t.notFinite, " not finite (made grey)"},
                                                  {t.negative, " negative (made zero)"},
                                                  {t.aboveOne, " above one (scaled down to one, hue kept)"}};
  for (const auto& [count, what] : kinds)
    if (count) out += (out.empty() ? "" : ", ") + std::to_string(count) + what;
  return out.empty() ? out : "texels that no reflectance can be: " + out;
}

}  // namespace

TextureData loadTexture(const std::string& path) {
#ifndef FREDHOLM_HAVE_OIIO
  throw Error("texture '" + path + "': cannot read it (this build has no OpenImageIO)");
#else
  const auto in = openImageInput(path, "texture");
  const OIIO::ImageSpec& spec = in->spec();
  // R, G, B, or one grey channel: only those are read (channels past them are never allocated).
  const int channels = spec.nchannels >= 3 ? 3 : 1;
  const size_t texels = size_t(spec.width) * size_t(spec.height);
  auto channel = [&](size_t p, int c) { return p * size_t(channels) + size_t(channels == 3 ? c : 0); };
  TextureData t;
  t.width = spec.width;
  t.height = spec.height;
  if (spec.format.basetype == OIIO::TypeDesc::UINT8) {
    std::vector<unsigned char> pixels(texels * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, pixels.data()))
      throw Error("texture '" + path + "': cannot decode it (" + in->geterror() + ")");
    t.format = TextureData::kSrgb8;
    t.words.resize(texels);
    for (size_t p = 0; p < texels; ++p)
      t.words[p] = uint32_t(pixels[channel(p, 0)]) | uint32_t(pixels[channel(p, 1)]) << 8 |
                   uint32_t(pixels[channel(p, 2)]) << 16;
    return t;
  }
  std::vector<float> pixels(texels * size_t(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw Error("texture '" + path + "': cannot decode it (" + in->geterror() + ")");
  // 16-bit images hold sRGB-encoded colour too; float images are linear already.
  const bool srgb = spec.format.basetype == OIIO::TypeDesc::UINT16;
  t.words.resize(4 * texels);
  for (size_t p = 0; p < texels; ++p) {
    float rgb[3];
    for (int c = 0; c < 3; ++c) rgb[c] = srgb ? srgbToLinear(pixels[channel(p, c)]) : pixels[channel(p, c)];
    mendReflectance(rgb, t);
    for (int c = 0; c < 3; ++c) t.words[4 * p + size_t(c)] = floatBits(rgb[c]);
    t.words[4 * p + 3] = floatBits(1.f);
  }
  return t;
#endif
}

PreparedScene prepareScene(const Scene& scene, const Bvh& bvh, const SceneFeatures& f, const EnvironmentMap* env) {
  PreparedScene prepared;
  prepared.features = f;
  prepared.deltaLobes = hasDeltaLobes(scene);
  prepared.lights = buildLightTable(scene, bvh, env);
  const EnvironmentMap black = makeEnvironmentMap("no environment map", 1, 1, {0.f, 0.f, 0.f}, 0.f, 1.f);
  const EnvironmentMap& map = env ? *env : black;
  prepared.environmentWidth = map.width;
  prepared.environmentHeight = map.height;
  prepared.environmentUShift = map.uShift();
  prepared.environment = map.packed();
  prepared.triangleMaterial = toBvhOrder(scene.triangleMaterial, bvh.order);
  prepared.materials = toGpuMaterials(scene);

  // Per-corner normals and UVs in BVH order, only where the scene uses them.
  // A kernel compiled with a feature the scene lacks (--all-features) gets neutral data:
  // zero normals, which the kernels read as "the geometric normal" exactly (a normal computed
  // here would differ from the kernel's in rounding, and so sample other directions), and
  // zero UVs.
  if (f.shadingNormals) {
    std::vector<float> source = scene.cornerNormals;
    if (source.empty()) source.assign(9 * scene.triangleCount(), 0.f);
    const std::vector<float> ordered = toBvhOrder(source, bvh.order, 9);
    for (size_t i = 0; i < ordered.size(); i += 3)
      prepared.cornerNormals.insert(prepared.cornerNormals.end(), {ordered[i], ordered[i + 1], ordered[i + 2], 0.f});
  }
  if (f.textures)
    prepared.cornerUVs = scene.cornerUVs.empty() ? std::vector<float>(6 * scene.triangleCount(), 0.f)
                                                 : toBvhOrder(scene.cornerUVs, bvh.order, 6);
  if (f.textures) {
    prepared.texels = srgbDecodeTable();
    for (size_t index = 0; index < scene.textures.size(); ++index) {
      const Texture& tex = scene.textures[index];
      std::string users;
      for (const Material& m : scene.materials)
        if (m.kdTexture == int(index)) users += (users.empty() ? "material '" : ", '") + m.name + "'";
      TextureData t;
      try {
        t = loadTexture(tex.path);
        const std::string repairs = mended(t);
        if (!repairs.empty())
          prepared.warnings.push_back(users + ": texture '" + tex.path + "': " + repairs);
      } catch (const Error& e) {
        prepared.warnings.push_back(users + ": " + e.what() + "; using a grey texel");
        t.width = t.height = 1;
        t.format = TextureData::kLinearFloat;
        t.words = {floatBits(0.5f), floatBits(0.5f), floatBits(0.5f), floatBits(1.f)};
      }
      prepared.textureInfo.insert(prepared.textureInfo.end(), {uint32_t(prepared.texels.size()), uint32_t(t.width),
                                                               uint32_t(t.height), uint32_t(t.format)});
      prepared.texels.insert(prepared.texels.end(), t.words.begin(), t.words.end());
    }
  }
  return prepared;
}

DeviceScene::DeviceScene(DeviceContext& dc, const PreparedScene& scene, const Bvh& hostBvh)
    : bvh(dc, hostBvh),
      features(scene.features),
      lightCount(unsigned(scene.lights.cdf.size())),
      environmentPick(scene.lights.environmentPick),
      environmentWidth(scene.environmentWidth),
      environmentHeight(scene.environmentHeight),
      environmentUShift(scene.environmentUShift) {
  buffers.nodes = bvh.nodes();
  buffers.blocks = bvh.blocks();
  buffers.triangles = bvh.triangles();
  buffers.triangle_material = upload(dc, scene.triangleMaterial, "triangle materials");
  buffers.materials = upload(dc, scene.materials, "materials");
  buffers.light_cdf = upload(dc, scene.lights.cdf, "light CDF");
  buffers.light_triangle = upload(dc, scene.lights.triangle, "light triangles");
  buffers.light_pdf_area = upload(dc, scene.lights.pdfArea, "light densities");
  buffers.normals = upload(dc, scene.cornerNormals, "shading normals");
  buffers.uvs = upload(dc, scene.cornerUVs, "texture coordinates");
  buffers.texels = upload(dc, scene.texels, "textures");
  buffers.texture_info = upload(dc, scene.textureInfo, "texture table");
  buffers.env_map = upload(dc, scene.environment, "environment map");
}

}  // namespace fh
