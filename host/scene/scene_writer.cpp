// OBJ/MTL writer: one vertex list, faces grouped by `usemtl` in triangle order.
#include "scene/scene_writer.h"

#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "base/atomic_file.h"
#include "base/output_plan.h"
#include "base/vec.h"
#include "base/error.h"
#include "image/image_io.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// Each file is composed in memory and written whole (base/atomic_file.h).
std::ostringstream textWriter() {
  std::ostringstream out;
  out << std::setprecision(9);  // round-trips a float
  return out;
}

void writeTriple(std::ostringstream& out, const char* key, const Vec3f& v) {
  out << key << ' ' << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
}

// A texture's path as the MTL in `mtlDir` names it: relative to that directory (as the loader
// resolves it), so the exported scene moves with its textures. Absolute where the two share
// no directory but the root: a path climbing to the root would only break when moved.
std::string texturePath(const std::string& texture, const fs::path& mtlDir) {
  const fs::path target = fs::absolute(texture).lexically_normal();
  size_t shared = 0;
  for (auto a = target.begin(), b = mtlDir.begin(); a != target.end() && b != mtlDir.end() && *a == *b; ++a, ++b)
    ++shared;
  const fs::path relative = target.lexically_relative(mtlDir);
  if (shared < 2 || relative.empty()) return target.generic_string();
  const std::string text = relative.generic_string();
  return text[0] == '-' ? "./" + text : text;  // a leading '-' would read as a texture option
}

std::string mtlText(const Scene& scene, const fs::path& mtlDir) {
  std::ostringstream out = textWriter();
  out << "# written by fredholm export from " << scene.sourcePath << "\n";
  for (const Material& m : scene.materials) {
    // tinyobjloader adds a material without a name for an empty library; no face can use it.
    if (m.name.empty()) continue;
    out << "\nnewmtl " << m.name << '\n';
    writeTriple(out, "Kd", m.kd);
    writeTriple(out, "Ks", m.ks);
    writeTriple(out, "Ke", m.ke);
    if (m.isGlass()) writeTriple(out, "Tf", m.tf);
    out << "Ns " << m.ns << "\nNi " << m.ni << "\nd " << m.d << "\nillum " << m.illum << '\n';
    if (m.kdTexture >= 0) out << "map_Kd " << texturePath(scene.textures[size_t(m.kdTexture)].path, mtlDir) << '\n';
  }
  return out.str();
}

std::string objText(const Scene& scene, const std::string& mtlName) {
  std::ostringstream out = textWriter();
  out << "# written by fredholm export from " << scene.sourcePath << "\nmtllib " << mtlName << '\n';
  const float toFile = 1.f / scene.worldScale;  // vertices in the file's units
  for (size_t v = 0; v < scene.vertexCount(); ++v) writeTriple(out, "v", scene.vertex(unsigned(v)) * toFile);
  const bool normals = !scene.cornerNormals.empty(), uvs = !scene.cornerUVs.empty();
  for (size_t c = 0; normals && c < scene.cornerNormals.size(); c += 3)
    out << "vn " << scene.cornerNormals[c] << ' ' << scene.cornerNormals[c + 1] << ' ' << scene.cornerNormals[c + 2]
        << '\n';
  for (size_t c = 0; uvs && c < scene.cornerUVs.size(); c += 2)
    out << "vt " << scene.cornerUVs[c] << ' ' << scene.cornerUVs[c + 1] << '\n';
  int material = -1;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (scene.triangleMaterial[t] != material) {
      material = scene.triangleMaterial[t];
      out << "usemtl " << scene.materials[size_t(material)].name << '\n';
    }
    out << 'f';
    for (size_t k = 0; k < 3; ++k) {
      const size_t corner = 3 * t + k + 1;  // normals and UVs are stored per corner
      out << ' ' << scene.indices[3 * t + k] + 1;
      if (uvs || normals) out << '/' << (uvs ? std::to_string(corner) : "");
      if (normals) out << '/' << corner;
    }
    out << '\n';
  }
  return out.str();
}

std::string cameraText(const Camera& c) {
  const nlohmann::json j = {{"eye", c.eye}, {"target", c.target}, {"up", c.up}, {"fov_y_deg", c.fovYDeg}};
  return j.dump() + "\n";
}

}  // namespace

std::vector<std::string> writeObjScene(const Scene& scene, const std::string& objPath, bool force) {
  if (fs::path(objPath).extension() != ".obj") throw Error("-o '" + objPath + "': the output must end in .obj");
  const std::string mtl = fs::path(objPath).replace_extension(".mtl").string();
  const std::string camera = fs::path(objPath).replace_extension(".camera.json").string();
  std::vector<std::string> paths = {objPath, mtl};
  if (scene.hasCamera) paths.push_back(camera);
  OutputPlan plan(force);
  for (const std::string& p : paths) plan.add(p, "-o");
  plan.reserve();
  plan.checkAgainstInputs();
  // The MTL first: the OBJ names it as written (a file that appeared meanwhile is kept).
  const std::string mtlWritten =
      writeTextAtomically(mtl, "-o", mtlText(scene, fs::absolute(mtl).parent_path().lexically_normal()));
  std::vector<std::string> written = {
      writeTextAtomically(objPath, "-o", objText(scene, fs::path(mtlWritten).filename().string())), mtlWritten};
  if (scene.hasCamera) written.push_back(writeTextAtomically(camera, "-o", cameraText(scene.camera)));
  plan.finish();
  return written;
}

}  // namespace fh
