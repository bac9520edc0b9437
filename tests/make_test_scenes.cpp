// make_test_scenes DIR: writes the test scenes that cannot ship as files into DIR, at build
// time (tests/CMakeLists.txt). They stand in for corpus scenes whose licenses forbid
// redistribution (the Stanford bunny, Dabrovic's Sponza: no commercial use) or state none
// (the Veach MIS scene's plates), and exercise what those scenes exercised:
//
// - blob/blob.obj: a closed, bumpy 81,920-triangle mesh with no materials and no normals
//   (the bunny's 70k-triangle scan); blob/CornellBox-Blob.obj puts it in a lit box.
// - colonnade/colonnade.obj: Sponza's troubles without its art. Long thin triangles
//   (column sides the full column's height, arches of thin beams crossing the nave
//   diagonally, hanging slivers) whose boxes overlap; concave quads; UVs beyond [0, 1];
//   no normals and no lights; textures of odd sizes, 1 and 3 channels, JPEG (baseline
//   and progressive) and PNG, named in the MTL with another letter case than on disk;
//   map_Ka, map_bump and bump lines, and the `Tf 1 1 1` of opaque materials.
// - veach/veach-plates.obj: four glossy plates, from near-mirror to rough, each turned to
//   reflect the camera's view onto a row of four sphere lights of equal power and radii
//   from 1/30 to 0.9 (Veach's multiple importance sampling scene, rebuilt from its idea),
//   plus a fill light.
//
// manifest.json lists each scene's triangle, emitter and texture counts as written here,
// which the loader's tests compare with what it reads. Output is deterministic.
#include <OpenImageIO/imageio.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/icosphere.h"

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

struct P3 {
  double x, y, z;
};
P3 operator+(P3 a, P3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
P3 operator-(P3 a, P3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
P3 operator*(P3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(P3 a, P3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
P3 cross(P3 a, P3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
P3 normalize(P3 a) { return a * (1.0 / std::sqrt(dot(a, a))); }

// An OBJ being written: positions, texture coordinates and faces grouped by material.
// Faces are counter-clockwise seen from their front.
class ObjFile {
 public:
  int vertex(P3 p) {
    positions_.push_back(p);
    return int(positions_.size());
  }
  int uv(double u, double v) {
    uvs_.push_back({u, v});
    return int(uvs_.size());
  }
  void use(const std::string& material) {
    if (material != current_) body_ += "usemtl " + material + "\n";
    current_ = material;
  }
  // A face over vertex indices (1-based), with texture coordinates when `uvs` is given.
  void face(const std::vector<int>& v, const std::vector<int>& uvs = {}) {
    std::string line = "f";
    for (size_t i = 0; i < v.size(); ++i)
      line += " " + std::to_string(v[i]) + (uvs.empty() ? "" : "/" + std::to_string(uvs[i]));
    body_ += line + "\n";
    triangles_ += v.size() - 2;
    if (emitting_) emissive_ += v.size() - 2;
  }
  void quad(P3 a, P3 b, P3 c, P3 d) { face({vertex(a), vertex(b), vertex(c), vertex(d)}); }
  // Following faces emit (counted for the manifest).
  void emitting(bool on) { emitting_ = on; }
  void comment(const std::string& text) { body_ += "# " + text + "\n"; }

  size_t triangles() const { return triangles_; }
  size_t emissiveTriangles() const { return emissive_; }

  void write(const fs::path& path, const std::string& header, const std::string& mtllib) const {
    std::ofstream out(path);
    out << header;
    if (!mtllib.empty()) out << "mtllib " << mtllib << "\n";
    char line[128];
    for (const P3& p : positions_) {
      std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", p.x, p.y, p.z);
      out << line;
    }
    for (const auto& t : uvs_) {
      std::snprintf(line, sizeof line, "vt %.6g %.6g\n", t[0], t[1]);
      out << line;
    }
    out << body_;
  }

 private:
  std::vector<P3> positions_;
  std::vector<std::array<double, 2>> uvs_;
  std::string body_, current_;
  size_t triangles_ = 0, emissive_ = 0;
  bool emitting_ = false;
};

void writeText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

void writeCamera(const fs::path& path, P3 eye, P3 target, double fovYDeg) {
  nlohmann::json j = {{"eye", {eye.x, eye.y, eye.z}},
                      {"target", {target.x, target.y, target.z}},
                      {"up", {0, 1, 0}},
                      {"fov_y_deg", fovYDeg}};
  writeText(path, j.dump() + "\n");
}

// The unit icosphere (scene/icosphere.h) with double coordinates, as the scenes are written.
struct Mesh {
  std::vector<P3> vertices;
  std::vector<std::array<unsigned, 3>> faces;
};
Mesh icosphere(int levels) {
  const fh::IndexedMesh unit = fh::icosphere(levels);
  Mesh m;
  for (const auto& v : unit.vertices) m.vertices.push_back({v[0], v[1], v[2]});
  m.faces = unit.faces;
  return m;
}

void addMesh(ObjFile& obj, const Mesh& mesh, P3 centre, double radius, double (*bump)(P3) = nullptr) {
  const int base = obj.vertex(centre + mesh.vertices[0] * (radius * (bump ? bump(mesh.vertices[0]) : 1.0))) - 1;
  for (size_t i = 1; i < mesh.vertices.size(); ++i)
    obj.vertex(centre + mesh.vertices[i] * (radius * (bump ? bump(mesh.vertices[i]) : 1.0)));
  for (const auto& f : mesh.faces) obj.face({base + int(f[0]) + 1, base + int(f[1]) + 1, base + int(f[2]) + 1});
}

// The blob's radius along a unit direction: smooth lumps, always positive (a star-shaped,
// closed surface that cannot intersect itself).
double blobRadius(P3 d) {
  return 1.0 + 0.22 * std::sin(3.1 * d.x + 0.4) * std::sin(2.3 * d.y + 1.1) * std::sin(2.7 * d.z + 0.2) +
         0.08 * std::sin(9.0 * d.x + 5.0 * d.y) * std::cos(7.0 * d.z) + 0.35 * std::max(0.0, d.y) * d.y;
}

struct Counts {
  size_t triangles, emissiveTriangles, emissiveMaterials, textures;
};

// The Cornell-like box: x in [-1, 1], y in [0, 2], z in [-1, 1], open at +z, red left,
// green right, a 0.47 x 0.38 light below the ceiling facing down.
void addBox(ObjFile& obj) {
  obj.use("floor");
  obj.quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1});
  obj.use("ceiling");
  obj.quad({-1, 2, 1}, {-1, 2, -1}, {1, 2, -1}, {1, 2, 1});
  obj.use("back");
  obj.quad({-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1});
  obj.use("left");
  obj.quad({-1, 0, 1}, {-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1});
  obj.use("right");
  obj.quad({1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1});
  obj.use("light");
  obj.emitting(true);
  obj.quad({-0.235, 1.98, -0.19}, {0.235, 1.98, -0.19}, {0.235, 1.98, 0.19}, {-0.235, 1.98, 0.19});
  obj.emitting(false);
}

const char* kBoxMaterials =
    "newmtl floor\nKd 0.725 0.71 0.68\n\nnewmtl ceiling\nKd 0.725 0.71 0.68\n\n"
    "newmtl back\nKd 0.725 0.71 0.68\n\nnewmtl left\nKd 0.63 0.065 0.05\n\n"
    "newmtl right\nKd 0.14 0.45 0.091\n\nnewmtl light\nKd 0.78 0.78 0.78\nKe 17 12 4\n\n"
    "newmtl blob\nKd 0.725 0.71 0.68\n";

std::map<std::string, Counts> writeBlob(const fs::path& dir) {
  fs::create_directories(dir);
  const Mesh mesh = icosphere(6);
  ObjFile alone;
  addMesh(alone, mesh, {0, 0, 0}, 1.0, blobRadius);
  for (int i = 0; i < 16; ++i) alone.vertex({0.01 * i, 0, 0});  // unreferenced, as scans have
  alone.write(dir / "blob.obj", "# A closed bumpy mesh (make_test_scenes): no materials, no normals.\n", "");
  writeCamera(dir / "blob.camera.json", {3.2, 0.8, 3.2}, {0, 0.2, 0}, 40);

  ObjFile boxed;
  addBox(boxed);
  boxed.use("blob");
  addMesh(boxed, mesh, {0.05, 0.45, -0.1}, 0.42, blobRadius);
  boxed.write(dir / "CornellBox-Blob.obj", "# The blob in a Cornell-like box (make_test_scenes).\n",
              "CornellBox-Blob.mtl");
  writeText(dir / "CornellBox-Blob.mtl", kBoxMaterials);
  writeCamera(dir / "CornellBox-Blob.camera.json", {0, 1, 3.9}, {0, 1, 0}, 39.3);
  return {{"blob/blob.obj", {alone.triangles(), 0, 0, 0}},
          {"blob/CornellBox-Blob.obj", {boxed.triangles(), boxed.emissiveTriangles(), 1, 0}}};
}

// A texture of `channels` 8-bit channels: stripes and a checker, so a wrong lookup shows.
void writeTexture(const fs::path& path, int width, int height, int channels, bool progressive) {
  std::vector<unsigned char> pixels(size_t(width) * size_t(height) * size_t(channels));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c) {
        const bool check = ((x / 8) + (y / 8)) % 2 == 0;
        const double v = 0.35 + 0.3 * check + 0.25 * std::sin(0.3 * x + 0.7 * c) * std::cos(0.2 * y);
        pixels[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + size_t(c)] =
            static_cast<unsigned char>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
      }
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) throw std::runtime_error("no image writer for " + path.string());
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  if (progressive) spec.attribute("jpeg:progressive", 1);
  if (!out->open(path.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

// A straight quad strip with texture coordinates: the quad a, b, c, d split into n along ab.
void texturedGrid(ObjFile& obj, P3 a, P3 b, P3 d, int nu, int nv, double uScale, double vScale) {
  std::vector<int> v, t;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double s = double(i) / nu, r = double(j) / nv;
      v.push_back(obj.vertex(a + (b - a) * s + (d - a) * r));
      t.push_back(obj.uv(s * uScale, r * vScale));
    }
  auto at = [&](int i, int j) { return size_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      obj.face({v[at(i, j)], v[at(i + 1, j)], v[at(i + 1, j + 1)], v[at(i, j + 1)]},
               {t[at(i, j)], t[at(i + 1, j)], t[at(i + 1, j + 1)], t[at(i, j + 1)]});
}

std::map<std::string, Counts> writeColonnade(const fs::path& dir) {
  fs::create_directories(dir);
  // On disk in one letter case, named in the MTL in another (as Sponza's are).
  writeTexture(dir / "floor_tiles.jpg", 320, 200, 3, false);
  writeTexture(dir / "Wall.png", 96, 150, 3, false);
  writeTexture(dir / "column.JPG", 77, 200, 1, true);
  writeTexture(dir / "rib.jpg", 64, 48, 3, true);
  writeTexture(dir / "wall-bump.jpg", 50, 50, 1, false);
  writeText(dir / "colonnade.mtl",
            "# Materials as a 3ds Max exporter writes them (make_test_scenes).\n"
            "newmtl floor\n\tNs 50\n\tNi 1.5\n\td 1\n\tTr 0\n\tTf 1 1 1 \n\tillum 2\n\tKa 0 0 0\n"
            "\tKd 0.75 0.71 0.67\n\tKs 0 0 0\n\tKe 0 0 0\n\tmap_Ka FLOOR_TILES.JPG\n\tmap_Kd FLOOR_TILES.JPG\n\n"
            "newmtl wall\n\tNs 20\n\tTf 1 1 1\n\tillum 2\n\tKd 0.6 0.58 0.5\n\tKs 0 0 0\n"
            "\tmap_Kd wall.PNG\n\tmap_bump WALL-BUMP.jpg\n\tbump WALL-BUMP.jpg\n\n"
            "newmtl column\n\tNs 10\n\tTf 1 1 1\n\tillum 2\n\tKd 0.7 0.7 0.7\n\tmap_Kd Column.jpg\n\n"
            "newmtl column_base\n\tTf 1 1 1\n\tillum 2\n\tKd 0.5 0.5 0.5\n\tmap_Kd COLUMN.JPG\n\tbump column.JPG\n\n"
            "newmtl rib\n\tTf 1 1 1\n\tillum 2\n\tKd 0.6 0.5 0.4\n\tmap_Kd RIB.JPG\n\n"
            "newmtl banner\n\tTf 1 1 1\n\tillum 2\n\tKd 0.5 0.1 0.1\n\n"
            "newmtl ornament\n\tillum 2\n\tKd 0.4 0.4 0.3\n\tKs 0.2 0.2 0.2\n\tNs 30\n");

  ObjFile obj;
  const double halfLength = 14, halfWidth = 6, columnHeight = 8;
  obj.use("floor");
  texturedGrid(obj, {-halfLength, 0, halfWidth}, {halfLength, 0, halfWidth}, {-halfLength, 0, -halfWidth}, 28,
               12, 7.5, -3.2);
  obj.use("wall");
  texturedGrid(obj, {-halfLength, 0, -halfWidth - 1}, {halfLength, 0, -halfWidth - 1},
               {-halfLength, 14, -halfWidth - 1}, 28, 14, 9.3, 4.4);
  texturedGrid(obj, {halfLength, 0, halfWidth + 1}, {-halfLength, 0, halfWidth + 1},
               {halfLength, 14, halfWidth + 1}, 28, 14, 9.3, 4.4);

  // Columns: twelve sides, each side two triangles the column's full height.
  const int sides = 12, columns = 10;
  auto columnX = [&](int i) { return -halfLength + 1.4 + i * (2 * halfLength - 2.8) / (columns - 1); };
  for (int row = -1; row <= 1; row += 2)
    for (int i = 0; i < columns; ++i) {
      const P3 foot{columnX(i), 0, row * (halfWidth - 0.5)};
      obj.use("column");
      for (int k = 0; k < sides; ++k) {
        const double a0 = 2 * kPi * k / sides, a1 = 2 * kPi * (k + 1) / sides;
        const P3 d0{std::cos(a0), 0, -std::sin(a0)}, d1{std::cos(a1), 0, -std::sin(a1)};
        const P3 up{0, columnHeight, 0};
        const int v[4] = {obj.vertex(foot + d0 * 0.3), obj.vertex(foot + d1 * 0.3), obj.vertex(foot + d1 * 0.3 + up),
                          obj.vertex(foot + d0 * 0.3 + up)};
        const int t[4] = {obj.uv(double(k) / sides, 0), obj.uv(double(k + 1) / sides, 0),
                          obj.uv(double(k + 1) / sides, 3.7), obj.uv(double(k) / sides, 3.7)};
        obj.face({v[0], v[1], v[2], v[3]}, {t[0], t[1], t[2], t[3]});
      }
      // A base whose top is a concave (arrow-shaped) quad: fan triangulation would fold it.
      obj.use("column_base");
      const P3 c = foot + P3{0, 0.05, 0};
      const int t0 = obj.uv(0, 0), t1 = obj.uv(1, 0), t2 = obj.uv(0.5, 0.3), t3 = obj.uv(0.5, 1);
      obj.face({obj.vertex(c + P3{-0.5, 0, 0.5}), obj.vertex(c + P3{0, 0, 0.1}), obj.vertex(c + P3{0.5, 0, 0.5}),
                obj.vertex(c + P3{0, 0, -0.5})},
               {t0, t2, t1, t3});
    }

  // Arches of thin square beams from each column top across the nave to the next column on
  // the far side, both ways: long diagonal beams whose boxes overlap each other.
  obj.use("rib");
  const int segments = 32;
  const double beam = 0.06;
  for (int i = 0; i + 1 < columns; ++i)
    for (int dirn = 0; dirn < 2; ++dirn) {
      const P3 from{columnX(dirn ? i + 1 : i), columnHeight, -(halfWidth - 0.5)};
      const P3 to{columnX(dirn ? i : i + 1), columnHeight, halfWidth - 0.5};
      auto along = [&](double s) { return from + (to - from) * s + P3{0, 3.5 * std::sin(kPi * s), 0}; };
      for (int k = 0; k < segments; ++k) {
        const P3 p0 = along(double(k) / segments), p1 = along(double(k + 1) / segments);
        const P3 axis = normalize(p1 - p0);
        const P3 side = normalize(cross(axis, {0, 1, 0})) * beam;
        const P3 up = normalize(cross(side, axis)) * beam;
        const P3 ring0[4] = {p0 - side - up, p0 + side - up, p0 + side + up, p0 - side + up};
        const P3 ring1[4] = {p1 - side - up, p1 + side - up, p1 + side + up, p1 - side + up};
        for (int e = 0; e < 4; ++e) {
          const int a = obj.vertex(ring0[e]), b = obj.vertex(ring0[(e + 1) % 4]), c = obj.vertex(ring1[(e + 1) % 4]),
                    d = obj.vertex(ring1[e]);
          const double u0 = double(k) / segments, u1 = double(k + 1) / segments;
          obj.face({a, b, c, d}, {obj.uv(u0, 0), obj.uv(u0, 1), obj.uv(u1, 1), obj.uv(u1, 0)});
        }
      }
    }

  // Hanging slivers: triangles a centimetre wide and metres long, leaning diagonally.
  obj.use("banner");
  for (int i = 0; i < 400; ++i) {
    const double x = -halfLength + 1 + (2 * halfLength - 2) * ((i * 37) % 400) / 400.0;
    const double z = -halfWidth + 1 + (2 * halfWidth - 2) * ((i * 91) % 400) / 400.0;
    const P3 top{x, 12.5, z}, bottom{x + 2.5 * std::sin(i * 0.7), 6.0 + std::sin(i * 1.3), z + 1.5 * std::cos(i)};
    const P3 width = normalize(cross(bottom - top, {0.3, 0.1, 1})) * 0.01;
    obj.face({obj.vertex(top - width), obj.vertex(top + width), obj.vertex(bottom)});
  }

  // Ornaments: a few quads folded along a diagonal (non-planar) on the walls.
  obj.use("ornament");
  for (int i = 0; i < 8; ++i) {
    const double x = -12 + 3.2 * i;
    obj.quad({x, 4, -halfWidth - 0.9}, {x + 1, 4, -halfWidth - 0.5}, {x + 1, 5, -halfWidth - 0.9},
             {x, 5, -halfWidth - 0.5});
  }

  obj.write(dir / "colonnade.obj", "# A colonnade with Sponza's geometric troubles (make_test_scenes).\n",
            "colonnade.mtl");
  writeCamera(dir / "colonnade.camera.json", {13, 1.6, -0.4}, {0, 3.5, 0}, 55);
  // Distinct textures used as diffuse colour: floor, wall, column (two materials, one file), rib.
  return {{"colonnade/colonnade.obj", {obj.triangles(), 0, 0, 4}}};
}

std::map<std::string, Counts> writeVeach(const fs::path& dir) {
  fs::create_directories(dir);
  const P3 eye{0, 2, 15}, target{0, -2, 2.5};
  // Lights in a row where the plates focus; radii from 1/30 to 0.9, radiance inversely
  // proportional to area so each emits the same power.
  const double radii[4] = {1.0 / 30.0, 0.1, 0.3, 0.9};
  const double xs[4] = {-3.75, -1.25, 1.25, 3.75};
  std::string mtl = "# Glossy plates and sphere lights (make_test_scenes). Ns = 2 / alpha^2 - 2 for Beckmann alpha\n"
                    "# 0.005, 0.02, 0.05, 0.1; Ni 2 gives the plates' Fresnel reflectance.\n";
  const char* ns[4] = {"79998", "4998", "798", "198"};
  for (int i = 0; i < 4; ++i)
    mtl += "newmtl plate" + std::to_string(i + 1) + "\nKd 0.07 0.09 0.13\nKs 1 1 1\nNs " + ns[i] +
           "\nNi 2.0\nillum 2\n\n";
  mtl += "newmtl floor\nKd 0.4 0.4 0.4\nKs 0 0 0\nillum 1\n\n";
  char line[160];
  for (int i = 0; i < 4; ++i) {
    std::snprintf(line, sizeof line, "newmtl light%d\nKd 0 0 0\nKe %.6g %.6g %.6g\nillum 0\n\n", i + 1,
                  1 / (radii[i] * radii[i]), 1 / (radii[i] * radii[i]), 1 / (radii[i] * radii[i]));
    mtl += line;
  }
  mtl += "newmtl fill\nKd 0 0 0\nKe 800 800 800\nillum 0\n";
  writeText(dir / "veach-plates.mtl", mtl);

  ObjFile obj;
  obj.use("floor");
  obj.quad({-10, -4.5, 10}, {10, -4.5, 10}, {10, -4.5, -10}, {-10, -4.5, -10});
  obj.quad({-10, -4.5, -6}, {10, -4.5, -6}, {10, 10, -6}, {-10, 10, -6});
  // Plates rise like steps away from the camera, so none hides the next. Each plate's normal
  // halves the angle between the directions to the camera and to the lights' row, so the
  // camera sees the lights mirrored in every plate.
  const P3 lightRow{0, 0, 0};
  const double plateZ[4] = {4.2, 3.0, 1.8, 0.6}, plateY[4] = {-3.7, -3.3, -2.9, -2.5};
  for (int i = 0; i < 4; ++i) {
    const P3 centre{0, plateY[i], plateZ[i]};
    const P3 n = normalize(normalize(eye - centre) + normalize(lightRow - centre));
    const P3 across{1, 0, 0};
    const P3 along = normalize(cross(n, across)) * 0.5;
    const P3 half = across * 4.5;
    obj.use("plate" + std::to_string(i + 1));
    obj.quad(centre - half - along, centre + half - along, centre + half + along, centre - half + along);
  }
  const Mesh sphere = icosphere(3);
  obj.emitting(true);
  for (int i = 0; i < 4; ++i) {
    obj.use("light" + std::to_string(i + 1));
    addMesh(obj, sphere, {xs[i], 0, 0}, radii[i]);
  }
  obj.use("fill");
  addMesh(obj, sphere, {10, 10, 4}, 0.5);
  obj.emitting(false);
  obj.write(dir / "veach-plates.obj", "# Veach's MIS scene rebuilt from its idea (make_test_scenes).\n",
            "veach-plates.mtl");
  writeCamera(dir / "veach-plates.camera.json", eye, target, 28);
  return {{"veach/veach-plates.obj", {obj.triangles(), obj.emissiveTriangles(), 5, 0}}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_test_scenes DIR\n");
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    nlohmann::json manifest = nlohmann::json::object();
    for (const auto& part : {writeBlob(dir / "blob"), writeColonnade(dir / "colonnade"), writeVeach(dir / "veach")})
      for (const auto& [path, c] : part)
        manifest[path] = {{"triangles", c.triangles},
                          {"emissive_triangles", c.emissiveTriangles},
                          {"emissive_materials", c.emissiveMaterials},
                          {"textures", c.textures}};
    writeText(dir / "manifest.json", manifest.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_test_scenes: error: %s\n", e.what());
    return 1;
  }
}
