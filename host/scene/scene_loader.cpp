// Scene loading: file checks, OBJ/MTL lint, tinyobjloader, then flattening into arrays.
#include "scene/scene_loader.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "base/error.h"
#include "base/input_file.h"
#include "base/vec.h"
#include "device/kernel_sources.h"
#include "scene/obj_lint.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// The path as given if it exists, else a case-insensitive match component by component
// (scene archives made on Windows name files in mixed case). Empty if nothing matches.
fs::path resolveCaseInsensitive(const fs::path& dir, const std::string& relative) {
  std::string normalized = relative;
  std::replace(normalized.begin(), normalized.end(), '\\', '/');
  fs::path exact = dir / normalized;
  std::error_code ec;
  if (fs::exists(exact, ec)) return exact;
  fs::path current = dir;
  for (const auto& part : fs::path(normalized)) {
    const std::string want = lower(part.string());
    fs::path found;
    for (const auto& entry : fs::directory_iterator(current, ec)) {
      if (lower(entry.path().filename().string()) == want) {
        found = entry.path();
        break;
      }
    }
    if (found.empty()) return {};
    current = found;
  }
  return current;
}

Vec3f toVec3(const tinyobj::real_t v[3]) { return {float(v[0]), float(v[1]), float(v[2])}; }

Material toMaterial(const tinyobj::material_t& m) {
  Material out;
  out.name = m.name;
  out.kd = toVec3(m.diffuse);
  out.ks = toVec3(m.specular);
  out.ke = toVec3(m.emission);
  out.tf = toVec3(m.transmittance);
  out.ns = float(m.shininess);
  out.ni = float(m.ior);
  out.d = float(m.dissolve);
  out.illum = m.illum;
  // Tf means transmission only for the glass models; opaque materials often carry
  // `Tf 1 1 1`, which must not turn walls and lights transparent.
  if (!out.isGlass()) out.tf = {0.f, 0.f, 0.f};
  return out;
}

struct SceneText {
  std::string objName;
  std::string obj;
  std::string mtl;  // every mtllib concatenated
  fs::path baseDir;  // where textures are looked up; empty for the built-in scene
};

void addTextures(Scene& scene, const std::vector<tinyobj::material_t>& source, const fs::path& baseDir) {
  std::map<std::string, int> byPath;
  for (size_t i = 0; i < source.size(); ++i) {
    const std::string& name = source[i].diffuse_texname;
    if (name.empty()) continue;
    const fs::path resolved = baseDir.empty() ? fs::path() : resolveCaseInsensitive(baseDir, name);
    if (resolved.empty()) {
      scene.warnings.push_back("material '" + source[i].name + "': texture '" + name +
                               "' not found; using its Kd instead");
      continue;
    }
    try {
      checkInputFile(resolved.string(), "texture");  // not a directory, a device, a FIFO
    } catch (const Error& e) {
      scene.warnings.push_back("material '" + source[i].name + "': " + e.what() + "; using its Kd instead");
      continue;
    }
    const std::string key = resolved.string();
    auto it = byPath.find(key);
    if (it == byPath.end()) {
      it = byPath.emplace(key, int(scene.textures.size())).first;
      scene.textures.push_back({key});
    }
    scene.materials[i].kdTexture = it->second;
  }
}


// Every index tinyobjloader produced refers to an element it read. The lint checks the file
// first, naming the line; this is the last line of defence should the two ever read a file
// differently, so that no index leaves the loader unchecked.
void checkIndices(const std::string& objName, const tinyobj::attrib_t& attrib,
                  const std::vector<tinyobj::shape_t>& shapes) {
  const size_t vertices = attrib.vertices.size() / 3, normals = attrib.normals.size() / 3,
               texcoords = attrib.texcoords.size() / 2;
  for (const auto& shape : shapes) {
    if (shape.mesh.indices.size() != 3 * shape.mesh.num_face_vertices.size() ||
        shape.mesh.material_ids.size() != shape.mesh.num_face_vertices.size())
      throw Error(objName + ": faces were not triangulated as expected");
    for (const auto& idx : shape.mesh.indices)
      if (idx.vertex_index < 0 || size_t(idx.vertex_index) >= vertices ||
          (idx.normal_index >= 0 && size_t(idx.normal_index) >= normals) ||
          (idx.texcoord_index >= 0 && size_t(idx.texcoord_index) >= texcoords))
        throw Error(objName + ": a face refers to a vertex, normal or texture coordinate the file does not define");
  }
}

// Scenes whose size (the largest side of the box around their faces' vertices) has an
// exponent within kWorldScaleBand of zero keep their units; others are scaled by a power of
// two to a size in [1, 2), never so far that a coordinate would pass 2^kMaxScaledExponent.
constexpr int kWorldScaleBand = 10;
constexpr int kMaxScaledExponent = 100;

// Scene::worldScale for these faces' vertices, applied to the positions.
float scaleToWorld(std::vector<float>& positions, const std::vector<tinyobj::shape_t>& shapes) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, magnitude = 0.0;
  for (const auto& shape : shapes)
    for (const auto& idx : shape.mesh.indices)
      for (size_t k = 0; k < 3; ++k) {
        const double v = positions[3 * size_t(idx.vertex_index) + k];
        lo[k] = std::min(lo[k], v);
        hi[k] = std::max(hi[k], v);
        magnitude = std::max(magnitude, std::fabs(v));
      }
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  // A scene of no size or of non-finite size is the lint's and the BVH's to refuse.
  int exponent = exponentTowardOne(size, kWorldScaleBand);
  if (exponent == 0) return 1.f;
  exponent = std::min(exponent, kMaxScaledExponent - std::ilogb(magnitude));
  for (float& p : positions) p = std::ldexp(p, exponent);
  return std::ldexp(1.f, exponent);
}

// A triangle's three corner normals scaled alike by a power of two (exact: their
// interpolation keeps its direction) where their largest component is as far from one as a
// scene's size that the loader scales, to one in [1, 2): the kernels normalize the
// interpolated normal through its square, which must neither over- nor underflow.
void bringNearUnitLength(float* normals) {
  float largest = 0.f;
  for (int i = 0; i < 9; ++i) largest = std::max(largest, std::fabs(normals[i]));
  const int exponent = exponentTowardOne(largest, kWorldScaleBand);
  for (int i = 0; exponent != 0 && i < 9; ++i) normals[i] = std::ldexp(normals[i], exponent);
}

void flattenShapes(Scene& scene, const tinyobj::attrib_t& attrib, const std::vector<tinyobj::shape_t>& shapes,
                   int defaultMaterial) {
  scene.positions.assign(attrib.vertices.begin(), attrib.vertices.end());
  scene.worldScale = scaleToWorld(scene.positions, shapes);
  bool anyNormals = false, anyUVs = false;
  for (const auto& shape : shapes)
    for (const auto& idx : shape.mesh.indices) {
      anyNormals |= idx.normal_index >= 0;
      anyUVs |= idx.texcoord_index >= 0;
    }
  size_t noMaterial = 0, degenerate = 0;
  for (const auto& shape : shapes) {
    const auto& mesh = shape.mesh;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t base = 3 * f;
      for (int k = 0; k < 3; ++k) scene.indices.push_back(unsigned(mesh.indices[base + size_t(k)].vertex_index));
      int material = mesh.material_ids[f];
      if (material < 0 || material >= defaultMaterial) {
        material = defaultMaterial;
        ++noMaterial;
      }
      scene.triangleMaterial.push_back(material);
      const size_t t = scene.triangleCount() - 1;
      const float3 a = scene.corner(t, 0), b = scene.corner(t, 1), c = scene.corner(t, 2);
      const float3 geometric = cross(b - a, c - a);
      if (!(length(geometric) > 0.f)) ++degenerate;
      for (int k = 0; k < 3; ++k) {
        const auto& idx = mesh.indices[base + size_t(k)];
        if (anyNormals) {
          const bool has = idx.normal_index >= 0;
          for (int j = 0; j < 3; ++j)
            scene.cornerNormals.push_back(has ? attrib.normals[3 * size_t(idx.normal_index) + size_t(j)]
                                              : geometric[size_t(j)]);
        }
        if (anyUVs) {
          const bool has = idx.texcoord_index >= 0;
          for (int j = 0; j < 2; ++j)
            scene.cornerUVs.push_back(has ? attrib.texcoords[2 * size_t(idx.texcoord_index) + size_t(j)] : 0.f);
        }
      }
      if (anyNormals) bringNearUnitLength(&scene.cornerNormals[9 * t]);
    }
  }
  if (noMaterial)
    scene.warnings.push_back(std::to_string(noMaterial) +
                             " triangle(s) have no material; they use the default grey diffuse (Kd 0.5)");
  if (degenerate) scene.warnings.push_back(std::to_string(degenerate) + " degenerate (zero-area) triangle(s)");
}

Scene buildScene(const SceneText& text, const ObjLintReport& report, const std::vector<std::string>& warnings) {
  Scene scene;
  scene.sourcePath = text.objName;
  scene.warnings = warnings;

  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text.obj, text.mtl, config))
    throw Error(text.objName + ": " + reader.Error());

  const auto& source = reader.GetMaterials();
  std::set<std::string> defined;
  for (const auto& m : source) {
    scene.materials.push_back(toMaterial(m));
    defined.insert(m.name);
  }
  for (const auto& use : report.usemtls)
    if (!defined.count(use.argument))
      scene.warnings.push_back(text.objName + ":" + std::to_string(use.line) + ": material '" + use.argument +
                               "' is not defined in the MTL; its faces use the default grey diffuse");
  const int defaultMaterial = int(scene.materials.size());
  Material grey;
  grey.name = "default";
  scene.materials.push_back(grey);

  checkIndices(text.objName, reader.GetAttrib(), reader.GetShapes());
  flattenShapes(scene, reader.GetAttrib(), reader.GetShapes(), defaultMaterial);
  if (scene.triangleCount() == 0) throw Error(text.objName + ": no triangles after triangulation");
  addTextures(scene, source, text.baseDir);
  collectLights(scene);
  return scene;
}

}  // namespace

void collectLights(Scene& scene) {
  size_t zeroArea = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const Material& m = scene.materials[size_t(scene.triangleMaterial[t])];
    if (!m.isEmissive()) continue;
    const float3 a = scene.corner(t, 0), b = scene.corner(t, 1), c = scene.corner(t, 2);
    const float area = 0.5f * length(cross(b - a, c - a));
    if (!(area > 0.f)) {
      ++zeroArea;
      continue;
    }
    scene.lights.push_back({unsigned(t), area, emittedPower(area, m.ke)});
  }
  if (zeroArea)
    scene.warnings.push_back(std::to_string(zeroArea) + " emissive triangle(s) have zero area and emit nothing");
  if (scene.lights.empty()) scene.warnings.push_back("the scene has no emissive triangles (no Ke): it has no lights");
}

void Scene::bounds(Vec3f& lo, Vec3f& hi) const {
  lo = {INFINITY, INFINITY, INFINITY};
  hi = {-INFINITY, -INFINITY, -INFINITY};
  for (unsigned i : indices) {
    lo = minv(lo, vertex(i));
    hi = maxv(hi, vertex(i));
  }
}

// The OBJ and MTL text tinyobjloader parses is the lints' (scene/obj_lint.h): what they read,
// line for line, so that no statement or number reaches the loader unchecked.
Scene loadScene(const std::string& objPath) {
  const fs::path path(objPath);
  SceneText text;
  text.objName = objPath;
  text.baseDir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  ObjLintReport report = lintObj(readInputFile(objPath, "scene"), objPath);
  text.obj = std::move(report.text);
  std::vector<std::string> warnings = report.warnings;

  std::set<std::string> used;
  for (const auto& use : report.usemtls) used.insert(use.argument);
  for (const auto& lib : report.mtllibs) {
    const std::string where = objPath + ":" + std::to_string(lib.line) + ": ";
    const fs::path mtlPath = resolveCaseInsensitive(text.baseDir, lib.argument);
    if (mtlPath.empty())
      throw Error(where + "material library '" + lib.argument + "' not found in " + text.baseDir.string());
    std::string mtl;
    try {
      mtl = readInputFile(mtlPath.string(), "mtllib");
    } catch (const Error& e) {
      throw Error(where + e.what());
    }
    // An empty library is legal: buildScene warns about every material it lacks.
    MtlLintReport lint = lintMtl(mtl, mtlPath.string(), &used);
    warnings.insert(warnings.end(), lint.warnings.begin(), lint.warnings.end());
    text.mtl += lint.text + "\n";
  }
  Scene scene = buildScene(text, report, warnings);

  const fs::path sidecar = fs::path(path).replace_extension(".camera.json");
  std::error_code ec;
  if (fs::exists(sidecar, ec)) {
    scene.camera = loadCameraJson(sidecar.string(), "camera");
    scene.hasCamera = true;
  }
  return scene;
}

Scene loadDefaultScene() {
  const std::string base = "scenes/cornell-box/CornellBox-Original";
  SceneText text;
  text.objName = "<built-in> " + base + ".obj";
  ObjLintReport report = lintObj(embeddedFile(base + ".obj"), text.objName);
  MtlLintReport mtl = lintMtl(embeddedFile(base + ".mtl"), "<built-in> " + base + ".mtl");
  text.obj = std::move(report.text);
  text.mtl = std::move(mtl.text);
  std::vector<std::string> warnings = report.warnings;
  warnings.insert(warnings.end(), mtl.warnings.begin(), mtl.warnings.end());
  Scene scene = buildScene(text, report, warnings);
  scene.camera = parseCameraJson(embeddedFile(base + ".camera.json"), "<built-in> " + base + ".camera.json");
  scene.hasCamera = true;
  return scene;
}

}  // namespace fh
