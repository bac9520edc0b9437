// Scene loading: every corpus scene loads with the counts its source states (the shared
// corpus' README for the shipped ones, the generator's manifest for the others), and every
// bad input gives a clear error naming the file (and line) or a documented warning.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "base/error.h"
#include "scene/scene_loader.h"
#include "scene/scene_writer.h"
#include "test_support.h"

namespace fh {
namespace {

using test::testScene;
using test::writeFile;

struct SceneCounts {
  const char* path;
  size_t triangles;
  size_t emissiveTriangles;
  size_t emissiveMaterials;
};

// The shipped scenes' triangle counts as the shared corpus' README states them
// (tinyobjloader, n-gons as n-2 triangles). Emitters: each Cornell light and the Mori light
// is one quad (2 triangles); the Glossy pair and water.obj have none.
const SceneCounts kShippedScenes[] = {
    {"cornell-box/CornellBox-Original.obj", 36, 2, 1},
    {"cornell-box/CornellBox-Mirror.obj", 36, 2, 1},
    {"cornell-box/CornellBox-Empty-RG.obj", 12, 2, 1},
    {"cornell-box/CornellBox-Empty-CO.obj", 12, 2, 1},
    {"cornell-box/CornellBox-Empty-White.obj", 12, 2, 1},
    {"cornell-box/CornellBox-Empty-Squashed.obj", 12, 2, 1},
    {"cornell-box/CornellBox-Sphere.obj", 2188, 2, 1},
    {"cornell-box/CornellBox-Water.obj", 7088, 2, 1},
    {"cornell-box/CornellBox-Glossy.obj", 1112, 0, 0},
    {"cornell-box/CornellBox-Glossy-Floor.obj", 1112, 0, 0},
    {"cornell-box/water.obj", 4900, 0, 0},
    {"cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj", 1112, 2, 1},
    {"mori-knob/testObj.obj", 11970, 2, 1},
};

void PrintTo(const SceneCounts& c, std::ostream* os) { *os << c.path; }

size_t emissiveMaterialsUsed(const Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (int m : scene.triangleMaterial) used[size_t(m)] = true;
  size_t n = 0;
  for (size_t m = 0; m < used.size(); ++m) n += used[m] && scene.materials[m].isEmissive();
  return n;
}

// What a loaded scene must look like, whatever its source.
void expectConsistent(const Scene& scene) {
  EXPECT_EQ(scene.triangleMaterial.size(), scene.triangleCount());
  for (unsigned i : scene.indices) ASSERT_LT(i, scene.vertexCount());
  for (float p : scene.positions) ASSERT_TRUE(std::isfinite(p));
  if (!scene.cornerNormals.empty()) {
    EXPECT_EQ(scene.cornerNormals.size(), 9 * scene.triangleCount());
  }
  if (!scene.cornerUVs.empty()) {
    EXPECT_EQ(scene.cornerUVs.size(), 6 * scene.triangleCount());
  }
  for (const Light& l : scene.lights) EXPECT_GT(l.area, 0.f);
}

class ShippedScene : public ::testing::TestWithParam<SceneCounts> {};

TEST_P(ShippedScene, LoadsWithReadmeCounts) {
  const SceneCounts& expected = GetParam();
  const Scene scene = loadScene(testScene(expected.path));
  EXPECT_EQ(scene.triangleCount(), expected.triangles);
  EXPECT_EQ(scene.lights.size(), expected.emissiveTriangles);
  EXPECT_EQ(emissiveMaterialsUsed(scene), expected.emissiveMaterials);
  expectConsistent(scene);
}

// The generated scenes against the counts their generator wrote down as it wrote the faces.
TEST(GeneratedScenes, LoadWithTheGeneratorsCounts) {
  const nlohmann::json manifest = test::readJson(test::generatedScene("manifest.json"));
  ASSERT_EQ(manifest.size(), 4u);
  for (const auto& [path, expected] : manifest.items()) {
    SCOPED_TRACE(path);
    const Scene scene = loadScene(test::generatedScene(path));
    EXPECT_EQ(scene.triangleCount(), expected.at("triangles").get<size_t>());
    EXPECT_EQ(scene.lights.size(), expected.at("emissive_triangles").get<size_t>());
    EXPECT_EQ(emissiveMaterialsUsed(scene), expected.at("emissive_materials").get<size_t>());
    EXPECT_EQ(scene.textures.size(), expected.at("textures").get<size_t>());
    expectConsistent(scene);
  }
}
std::string sceneName(const ::testing::TestParamInfo<SceneCounts>& info) {
  std::string name = std::filesystem::path(info.param.path).stem().string();
  if (std::string(info.param.path).find("legacy") != std::string::npos) name = "Legacy" + name;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Corpus, ShippedScene, ::testing::ValuesIn(kShippedScenes), sceneName);

TEST(SceneLoader, CornellLightAndMaterialsAsInMtl) {
  const Scene scene = loadDefaultScene();
  EXPECT_EQ(scene.triangleCount(), 36u);
  ASSERT_EQ(scene.lights.size(), 2u);
  const Material& light = scene.materials[size_t(scene.triangleMaterial[scene.lights[0].triangle])];
  EXPECT_EQ(light.ke, (Vec3f{17.f, 12.f, 4.f}));
  // The light quad's area: 0.47 x 0.38 at y = 1.98 (two triangles share it).
  EXPECT_NEAR(scene.lights[0].area + scene.lights[1].area, 0.47f * 0.38f, 2e-3f);
  // Tf 1 1 1 on an opaque material means nothing.
  EXPECT_EQ(light.tf, (Vec3f{0.f, 0.f, 0.f}));
  EXPECT_TRUE(scene.hasCamera);
  EXPECT_FLOAT_EQ(scene.camera.fovYDeg, 39.3f);
}

TEST(SceneLoader, GlossyArchiveMissingLightMaterialWarnsAndUsesDefault) {
  const Scene scene = loadScene(testScene("cornell-box/CornellBox-Glossy.obj"));
  bool warned = false;
  for (const auto& w : scene.warnings) warned |= w.find("'light' is not defined") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_EQ(scene.materials.back().name, "default");
}

// The colonnade's MTL names every texture in another letter case than its file's, as
// Sponza's does; two materials name the same file in two cases.
TEST(SceneLoader, TexturesResolveCaseInsensitively) {
  const Scene scene = loadScene(testScene("colonnade/colonnade.obj"));
  EXPECT_EQ(scene.textures.size(), 4u);
  for (const auto& w : scene.warnings) EXPECT_EQ(w.find("texture"), std::string::npos) << w;
  for (const auto& t : scene.textures) EXPECT_TRUE(std::filesystem::exists(t.path)) << t.path;
  EXPECT_FALSE(scene.cornerUVs.empty());
}

TEST(SceneLoader, SmoothNormalsKeptOnlyWhereTheFileHasThem) {
  EXPECT_FALSE(loadScene(testScene("cornell-box/CornellBox-Sphere.obj")).cornerNormals.empty());
  EXPECT_TRUE(loadScene(testScene("cornell-box/CornellBox-Original.obj")).cornerNormals.empty());
}

// ---- Small scenes written by the tests ----

class BadInput : public ::testing::Test {
 protected:
  std::string dir = test::tempDir("loader");
  std::string path(const std::string& name) const { return dir + "/" + name; }

  // Loads `obj` (written to scene.obj) and returns the error message, or "" if it loaded.
  std::string errorFor(const std::string& obj, const std::string& mtl = "") {
    writeFile(path("scene.obj"), obj);
    if (!mtl.empty()) writeFile(path("scene.mtl"), mtl);
    try {
      loadScene(path("scene.obj"));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }
};

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST_F(BadInput, MissingFile) {
  try {
    loadScene(path("nothing.obj"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene '" + path("nothing.obj") + "': file not found"), std::string::npos)
        << e.what();
  }
}

TEST_F(BadInput, DirectoryInsteadOfFile) {
  std::filesystem::create_directory(path("dir.obj"));
  try {
    loadScene(path("dir.obj"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST_F(BadInput, EmptyFile) {
  EXPECT_NE(errorFor("").find("scene.obj: no faces"), std::string::npos);
}

TEST_F(BadInput, OnlyComments) {
  EXPECT_NE(errorFor("# nothing here\n\n").find("no faces"), std::string::npos);
}

TEST_F(BadInput, NaNVertex) {
  EXPECT_NE(errorFor("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").find("scene.obj:2: non-finite value 'nan'"),
            std::string::npos);
}

TEST_F(BadInput, InfiniteVertex) {
  EXPECT_NE(errorFor("v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n").find("scene.obj:3: non-finite"), std::string::npos);
  // Finite in the file but not as a float.
  EXPECT_NE(errorFor("v 0 0 0\nv 1e40 0 0\nv 0 1 0\nf 1 2 3\n").find("scene.obj:2: non-finite"), std::string::npos);
}

TEST_F(BadInput, MalformedVertex) {
  EXPECT_NE(errorFor("v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n").find("scene.obj:2: 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(errorFor("v 0 0\n").find("scene.obj:1: 'v' needs 3 to 7 numbers"), std::string::npos);
}

TEST_F(BadInput, MalformedFaces) {
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1 2\n").find("scene.obj:4: face needs at least three"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1/x 2 3\n").find("scene.obj:4: face element '1/x'"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 0 1 2\n").find("scene.obj:4: face element '0' uses index 0"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1/2/3/4 2 3\n").find("scene.obj:4:"), std::string::npos);
}

TEST_F(BadInput, IndicesOutOfRange) {
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1 2 9\n").find("scene.obj:4: vertex index 9 out of range"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f -5 -2 -1\n")
                .find("scene.obj:4: relative vertex index -5 out of range (3 defined so far)"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "vn 0 0 1\nf 1//1 2//2 3//1\n").find("scene.obj:5: normal index 2"),
            std::string::npos);
}

// Found by fuzzing: inputs the lint passed and the loader read
// differently, which crashed or sent out-of-range indices to the device.
TEST_F(BadInput, FaceElementEndingInASlash) {
  EXPECT_NE(errorFor("v 1 0 0\nv 0 1 0\nv 0 1 0\nf 1/ 2 3\n").find("scene.obj:4: face element '1/' ends in '/'"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1// 2 3\n").find("scene.obj:4: face element '1//' ends in '/'"),
            std::string::npos);
}

TEST_F(BadInput, LinesSplitOnlyWhereTheLoaderSplitsThem) {
  EXPECT_NE(errorFor("v\r1 1 0\nf 1 1 1\n").find("scene.obj:1: a carriage return without a line feed"),
            std::string::npos);
  // A lone CR ends a comment for the loader: the face behind it must not pass unchecked.
  EXPECT_NE(errorFor(std::string(kTriangle) + "# c\rf 1 2 99\nf 1 2 3\n").find("scene.obj:4: a carriage return"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "\vv 1 1 0\nf 1 2 3\n").find("scene.obj:4: control character 0x0b"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1 2 3\n" + std::string(1, '\0') + "f 1 2 99\n")
                .find("scene.obj:5: control character 0x00"),
            std::string::npos);
  EXPECT_NE(errorFor("mtllib scene.mtl\n" + std::string(kTriangle) + "usemtl a\nf 1 2 3\n", "newmtl a\rKd 1 1 1\n")
                .find("scene.mtl:1: a carriage return"),
            std::string::npos);
}

TEST_F(BadInput, IndicesBeyondAnyIntegerType) {
  EXPECT_NE(errorFor(std::string(kTriangle) + "f -9223372036854775808 2 3\n").find("scene.obj:4: face element"),
            std::string::npos);
  EXPECT_NE(errorFor(std::string(kTriangle) + "f 1 99999999999999999999 3\n").find("out of any file's range"),
            std::string::npos);
}

// Devices and FIFOs would block or never end: refused by name.
TEST_F(BadInput, FilesThatAreNotRegularFiles) {
  EXPECT_NE(errorFor("mtllib /dev/zero\n" + std::string(kTriangle) + "f 1 2 3\n")
                .find("scene.obj:1: mtllib '/dev/zero': is not a regular file"),
            std::string::npos);
  ASSERT_EQ(::mkfifo(path("fifo.obj").c_str(), 0600), 0);
  try {
    loadScene(path("fifo.obj"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene '" + path("fifo.obj") + "': is not a regular file"), std::string::npos)
        << e.what();
  }
  writeFile(path("t.mtl"), "newmtl a\nKd 1 1 1\nmap_Kd fifo.obj\n");
  writeFile(path("t.obj"), "mtllib t.mtl\n" + std::string(kTriangle) + "usemtl a\nf 1 2 3\n");
  const Scene scene = loadScene(path("t.obj"));
  bool warned = false;
  for (const auto& w : scene.warnings) warned = warned || w.find("is not a regular file") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_TRUE(scene.textures.empty());
}

// Only the materials the OBJ uses are kept: memory follows the scene, not the library
// (a million unused materials once cost gigabytes).
TEST_F(BadInput, UnusedMaterialsAreNotKept) {
  std::string mtl = "# a big library\n";
  for (int i = 0; i < 20000; ++i) mtl += "newmtl m" + std::to_string(i) + "\nKd 0.5 0.5 0.5\n";
  mtl += "newmtl light\nKe 1 1 1\n";
  writeFile(path("big.mtl"), mtl);
  writeFile(path("big.obj"), "mtllib big.mtl\n" + std::string(kTriangle) + "usemtl m17\nf 1 2 3\nusemtl light\nf 3 2 1\n");
  const Scene scene = loadScene(path("big.obj"));
  ASSERT_EQ(scene.materials.size(), 3u);  // m17, light and the default grey
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[0])].name, "m17");
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[1])].name, "light");
  EXPECT_EQ(scene.lights.size(), 1u);
}

TEST_F(BadInput, MissingMtl) {
  EXPECT_NE(errorFor(std::string("mtllib gone.mtl\n") + kTriangle + "f 1 2 3\n")
                .find("scene.obj:1: material library 'gone.mtl' not found"),
            std::string::npos);
}

TEST_F(BadInput, MtlIsADirectory) {
  std::filesystem::create_directory(path("lib.mtl"));
  EXPECT_NE(errorFor(std::string("mtllib lib.mtl\n") + kTriangle + "f 1 2 3\n").find("is a directory"),
            std::string::npos);
}

TEST_F(BadInput, MalformedMtl) {
  const std::string obj = std::string("mtllib scene.mtl\n") + kTriangle + "usemtl a\nf 1 2 3\n";
  EXPECT_NE(errorFor(obj, "newmtl a\nKd 0.5 abc 0.5\n").find("scene.mtl:2: 'abc' is not a number in 'Kd'"),
            std::string::npos);
  EXPECT_NE(errorFor(obj, "newmtl a\nKe nan 1 1\n").find("scene.mtl:2: non-finite value"), std::string::npos);
  EXPECT_NE(errorFor(obj, "Kd 1 1 1\nnewmtl a\n").find("scene.mtl:1: 'Kd' before any 'newmtl'"),
            std::string::npos);
  EXPECT_NE(errorFor(obj, "newmtl a\nillum\n").find("scene.mtl:2: 'illum' needs 1 numbers"), std::string::npos);
}

TEST_F(BadInput, ZeroByteMtlWarnsAndUsesDefaultMaterial) {
  writeFile(path("scene.mtl"), "");
  writeFile(path("scene.obj"), std::string("mtllib scene.mtl\n") + kTriangle + "usemtl red\nf 1 2 3\n");
  const Scene scene = loadScene(path("scene.obj"));
  ASSERT_FALSE(scene.warnings.empty());
  EXPECT_NE(scene.warnings[0].find("scene.obj:5: material 'red' is not defined"), std::string::npos)
      << scene.warnings[0];
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[0])].name, "default");
}

TEST_F(BadInput, MissingTextureWarnsAndFallsBackToKd) {
  writeFile(path("scene.mtl"), "newmtl t\nKd 0.2 0.3 0.4\nmap_Kd nowhere.png\n");
  writeFile(path("scene.obj"), std::string("mtllib scene.mtl\n") + kTriangle + "usemtl t\nf 1 2 3\n");
  const Scene scene = loadScene(path("scene.obj"));
  bool warned = false;
  for (const auto& w : scene.warnings) warned |= w.find("texture 'nowhere.png' not found") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_EQ(scene.materials[0].kdTexture, -1);
}

TEST_F(BadInput, FaceWithoutMaterialGetsDefaultGreyAndWarning) {
  writeFile(path("scene.obj"), std::string(kTriangle) + "f 1 2 3\n");
  const Scene scene = loadScene(path("scene.obj"));
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[0])].kd, (Vec3f{0.5f, 0.5f, 0.5f}));
  bool warned = false;
  for (const auto& w : scene.warnings) warned |= w.find("no material") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST_F(BadInput, BinaryGarbage) {
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage.push_back(char((i * 7919) % 256));
  EXPECT_NE(errorFor(garbage).find("scene.obj"), std::string::npos);
}

TEST_F(BadInput, CliReportsOneLineAndFails) {
  writeFile(path("bad.obj"), "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  const auto r = test::runFredholm("render " + path("bad.obj") + " -o " + path("out.png"));
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("fredholm: error: " + path("bad.obj") + ":2: non-finite value 'nan'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(path("out.png")));
}

// ---- MTL read as the specification reads it, materials as physics allows ----

// True when the scene's only warning is the one every scene without Ke gets.
::testing::AssertionResult onlyNoLights(const Scene& scene) {
  for (const auto& w : scene.warnings)
    if (w.find("it has no lights") == std::string::npos) return ::testing::AssertionFailure() << "warning: " << w;
  return ::testing::AssertionSuccess();
}

class Mtl : public BadInput {
 protected:
  // Loads a triangle using material `use` of `mtl`; returns the scene.
  Scene load(const std::string& mtl, const std::string& use = "a") {
    writeFile(path("scene.mtl"), mtl);
    writeFile(path("scene.obj"), "mtllib scene.mtl\n" + std::string(kTriangle) + "usemtl " + use + "\nf 1 2 3\n");
    return loadScene(path("scene.obj"));
  }
  static const Material& used(const Scene& scene) { return scene.materials[size_t(scene.triangleMaterial[0])]; }
  std::string mtlError(const std::string& mtl) {
    return errorFor("mtllib scene.mtl\n" + std::string(kTriangle) + "usemtl a\nf 1 2 3\n", mtl);
  }
  // The warnings holding `text`.
  static std::vector<std::string> warningsWith(const Scene& scene, const std::string& text) {
    std::vector<std::string> found;
    for (const auto& w : scene.warnings)
      if (w.find(text) != std::string::npos) found.push_back(w);
    return found;
  }
};

// One value means grey (r = g = b), not (v, 0, 0): `Kd 0.5` is a grey floor, not a red one.
TEST_F(Mtl, OneValueIsGrey) {
  const Scene scene = load("newmtl a\nillum 2\nKa 0.1\nKd 0.5\nKs 0.25\nKe 10\n");
  const Material& m = used(scene);
  EXPECT_EQ(m.kd, (Vec3f{0.5f, 0.5f, 0.5f}));
  EXPECT_EQ(m.ks, (Vec3f{0.25f, 0.25f, 0.25f}));
  EXPECT_EQ(m.ke, (Vec3f{10.f, 10.f, 10.f}));
  // The light emits white: pi * area * Ke in every channel.
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].power[0], scene.lights[0].power[1]);
  EXPECT_EQ(scene.lights[0].power[0], scene.lights[0].power[2]);
  EXPECT_NEAR(scene.lights[0].power[2], float(M_PI) * 0.5f * 10.f, 1e-4f);
  // Tf (and its other name Kt) of a glass.
  EXPECT_EQ(used(load("newmtl g\nillum 7\nNi 1.5\nTf 0.8\n", "g")).tf, (Vec3f{0.8f, 0.8f, 0.8f}));
  EXPECT_EQ(used(load("newmtl g\nillum 7\nNi 1.5\nKt 0.7\n", "g")).tf, (Vec3f{0.7f, 0.7f, 0.7f}));
  // Three values as before; a trailing comment is not a value.
  EXPECT_EQ(used(load("newmtl a\nKd 0.1 0.2 0.3\n")).kd, (Vec3f{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(used(load("newmtl a\nKd 0.4 # grey\n")).kd, (Vec3f{0.4f, 0.4f, 0.4f}));
}

TEST_F(Mtl, TwoValuesSpectralAndXyzRefused) {
  for (const char* key : {"Ka", "Kd", "Ks", "Ke", "Tf", "Kt"}) {
    SCOPED_TRACE(key);
    const std::string k = key;
    EXPECT_NE(mtlError("newmtl a\n" + k + " 0.5 0.5\n").find("scene.mtl:2: '" + k + "' needs one or three numbers"),
              std::string::npos);
    EXPECT_NE(mtlError("newmtl a\n" + k + " spectral file.rfl\n")
                  .find("scene.mtl:2: MTL spectral colours are not supported ('" + k + " spectral')"),
              std::string::npos);
    EXPECT_NE(mtlError("newmtl a\n" + k + " xyz 0.3 0.4 0.5\n")
                  .find("scene.mtl:2: MTL xyz colours are not supported ('" + k + " xyz')"),
              std::string::npos);
  }
}

TEST_F(Mtl, NegativeColoursRefused) {
  for (const char* key : {"Ka", "Kd", "Ks", "Ke", "Tf", "Kt"}) {
    SCOPED_TRACE(key);
    const std::string k = key;
    const std::string e = mtlError("newmtl a\nillum 2\n" + k + " 0.5 -0.1 0.5\n");
    EXPECT_NE(e.find("scene.mtl:3: material 'a': negative " + k), std::string::npos) << e;
    EXPECT_NE(mtlError("newmtl a\n" + k + " -0.5\n").find("scene.mtl:2: material 'a': negative " + k),
              std::string::npos);
  }
  // In a material the OBJ does not use too: the lint reads the whole file.
  EXPECT_NE(mtlError("newmtl a\nKd 1 1 1\nnewmtl b\nKe 10 -1 10\n").find("scene.mtl:4: material 'b': negative Ke"),
            std::string::npos);
}

TEST_F(Mtl, ImpossibleIndexOfRefractionAndExponentRefused) {
  EXPECT_NE(mtlError("newmtl a\nillum 7\nNi 0\n").find("scene.mtl:3: material 'a': Ni 0"), std::string::npos);
  EXPECT_NE(mtlError("newmtl a\nNi -1\n").find("scene.mtl:2: material 'a': Ni -1"), std::string::npos);
  EXPECT_NE(mtlError("newmtl a\nNs -5\n").find("scene.mtl:2: material 'a': negative Ns"), std::string::npos);
  EXPECT_NE(mtlError("newmtl a\nillum 2.5\n").find("scene.mtl:2: 'illum 2.5' is not a whole number"),
            std::string::npos);
  // What is valid loads as before.
  const Scene scene = load("newmtl a\nillum 7\nNi 1.33\nNs 0\n");
  const Material& m = used(scene);  // the scene outlives the reference
  EXPECT_FLOAT_EQ(m.ni, 1.33f);
  EXPECT_EQ(m.ns, 0.f);
  EXPECT_EQ(m.illum, 7);
}

// A reflectance the renderer uses may not exceed one: Kd 5 5 5 would reflect five times the
// light it receives. The BSDF (kernels/bsdf.h) gives the diffuse lobe only what the specular
// Fresnel leaves over, so Kd and Ks are each at most one, not their sum (test_bsdf's
// AlbedoNeverExceedsOne covers Kd 1 with Ks 1).
TEST_F(Mtl, ReflectanceAboveOneScaledDownWithAWarning) {
  Scene scene = load("newmtl a\nillum 2\nKd 5 5 5\n");
  EXPECT_EQ(used(scene).kd, (Vec3f{1.f, 1.f, 1.f}));
  ASSERT_EQ(warningsWith(scene, "scene.mtl:3: material 'a': Kd 5 5 5 reflects more light than it receives").size(), 1u);

  // The hue is kept: every channel is scaled by the largest.
  scene = load("# glossy\nnewmtl a\nKs 2 1 0.5\nKd 0.2 0.4 1.6\nillum 3\nNs 1000\n");
  EXPECT_EQ(used(scene).ks, (Vec3f{1.f, 0.5f, 0.25f}));
  EXPECT_EQ(used(scene).kd, (Vec3f{0.125f, 0.25f, 1.f}));
  EXPECT_EQ(warningsWith(scene, "scene.mtl:3: material 'a': Ks 2 1 0.5").size(), 1u);
  EXPECT_EQ(warningsWith(scene, "scene.mtl:4: material 'a': Kd 0.2 0.4 1.6").size(), 1u);

  // The last statement counts, as the loader reads it.
  EXPECT_EQ(used(load("newmtl a\nKd 3 3 3\nKd 0.5 0.5 0.5\n")).kd, (Vec3f{0.5f, 0.5f, 0.5f}));

  // A glass transmits at most what it receives.
  scene = load("newmtl g\nillum 7\nNi 1.5\nTf 2 2 1\n", "g");
  EXPECT_EQ(used(scene).tf, (Vec3f{1.f, 1.f, 0.5f}));
  EXPECT_EQ(warningsWith(scene, "material 'g': Tf 2 2 1 transmits more light").size(), 1u);

  // Values the renderer does not use are left alone: Ks of a diffuse-only model (illum 1).
  scene = load("newmtl a\nillum 1\nKd 0.5 0.5 0.5\nKs 3 3 3\n");
  EXPECT_EQ(used(scene).ks, (Vec3f{3.f, 3.f, 3.f}));
  EXPECT_TRUE(warningsWith(scene, "more light").empty());

  // Kd and Ks each at most one: energy is conserved, nothing changes (the glossy Cornell
  // boxes' spheres have Kd + Ks of 1.36 to 1.56).
  scene = load("newmtl a\nillum 2\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 40\n");
  EXPECT_EQ(used(scene).kd, (Vec3f{0.8f, 0.8f, 0.8f}));
  EXPECT_EQ(used(scene).ks, (Vec3f{0.5f, 0.5f, 0.5f}));
  EXPECT_TRUE(onlyNoLights(scene));
}

// The MTL glass models (illum 4, 6, 7, 9) have a diffuse Kd and a specular Ks too; fredholm's
// glass reflects by Fresnel's law alone and tints what it transmits by Tf, so a Kd or Ks
// above zero there is said to be unused, at its line. Zero is what the glass renders.
TEST_F(Mtl, GlassSaysItsKdAndKsAreUnused) {
  Scene scene = load("newmtl g\nillum 7\nNi 1.5\nKd 0.8 0 0\nKs 0.3 0.3 0.3\nTf 0.9\n", "g");
  EXPECT_EQ(warningsWith(scene, "scene.mtl:4: material 'g': Kd 0.8 0 0 and Ks 0.3 0.3 0.3 not used by glass (illum 7)")
                .size(),
            1u);
  scene = load("newmtl g\nKs 0.5\nillum 4\nNi 1.5\nKd 0 0 0\nTf 0.9\n", "g");
  EXPECT_EQ(warningsWith(scene, "scene.mtl:2: material 'g': Ks 0.5 0.5 0.5 not used by glass (illum 4)").size(), 1u);
  scene = load("newmtl g\nillum 4\nNi 1.5\nKd 0 0 0\nTf 0.9\n", "g");
  EXPECT_TRUE(warningsWith(scene, "not used by glass").empty());
  // The same Kd on a diffuse model is used: nothing said.
  EXPECT_TRUE(warningsWith(load("newmtl a\nillum 2\nKd 0.8 0 0\n"), "not used").empty());
}

// What the renderer ignores is said once per kind of statement, naming the first line.
TEST_F(Mtl, IgnoredStatementsWarnedOncePerKind) {
  const Scene scene = load(
      "newmtl a\nKd 0.5\nd 0.5\nTr 0.2\nillum 11\nbump b.png\nsharpness 60\nmap_Ks s.png\nfoo 1 2\n"
      "newmtl b\nd 0.25\nillum -1\nbump c.png\nfoo 3\nmap_Kd -s 2 2 2 t.png\n"
      "newmtl unused\nd 0.1\nbar 1\n",
      "a\nf 1 2 3\nusemtl b");
  const std::pair<const char*, const char*> expected[] = {
      {"scene.mtl:3: 'd' (dissolve)", "2 statements, the first in material 'a'"},
      {"scene.mtl:4: 'Tr' (transparency)", "1 statement"},
      {"scene.mtl:5: illum 11 is not a model", "2 statements"},
      {"scene.mtl:6: 'bump' is ignored", "2 statements"},
      {"scene.mtl:7: 'sharpness' is ignored", "1 statement"},
      {"scene.mtl:8: 'map_Ks' is ignored", "1 statement"},
      {"scene.mtl:9: ignored unknown statement 'foo'", "2 statements"},
      {"scene.mtl:15: map_Kd option '-s' is ignored", "1 statement"},
  };
  for (const auto& [start, count] : expected) {
    SCOPED_TRACE(start);
    const auto found = warningsWith(scene, start);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_NE(found[0].find(count), std::string::npos) << found[0];
  }
  // Nothing about the material no face uses; unknown illum models render as illum 2.
  EXPECT_TRUE(warningsWith(scene, "'bar'").empty());
  EXPECT_TRUE(warningsWith(scene, ":17:").empty());
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[0])].illum, 2);
  EXPECT_EQ(scene.materials[size_t(scene.triangleMaterial[1])].illum, 2);
  // The opaque defaults (d 1, Tr 0) and Ka say nothing the renderer ignores.
  EXPECT_TRUE(onlyNoLights(load("newmtl a\nKa 0.2 0.2 0.2\nd 1\nTr 0\nillum 2\nKd 0.5\n")));
}

// The lint and the loader read one text: a comment after a name is not part of the name.
TEST_F(Mtl, NamesAndFileNamesReadAsTheLintReadsThem) {
  writeFile(path("t.png"), "not decoded by the loader");
  const Scene scene = load("newmtl a # the floor\nKd 0.2 0.3 0.4\nmap_Kd t.png # its texture\n");
  EXPECT_EQ(used(scene).name, "a");
  EXPECT_EQ(used(scene).kd, (Vec3f{0.2f, 0.3f, 0.4f}));
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_TRUE(std::filesystem::equivalent(scene.textures[0].path, path("t.png")));
  EXPECT_TRUE(onlyNoLights(scene));
}

// ---- Text the lint must see as the loader does ----

const std::string kBom = "\xEF\xBB\xBF";

TEST_F(BadInput, ByteOrderMarkSkipped) {
  writeFile(path("scene.mtl"), kBom + "newmtl red\nKd 0.8 0.1 0.1\n");
  writeFile(path("scene.obj"), kBom + "mtllib scene.mtl\n" + std::string(kTriangle) + "usemtl red\nf 1 2 3\n");
  const Scene scene = loadScene(path("scene.obj"));
  const Material& m = scene.materials[size_t(scene.triangleMaterial[0])];
  EXPECT_EQ(m.name, "red");
  EXPECT_EQ(m.kd, (Vec3f{0.8f, 0.1f, 0.1f}));
  EXPECT_TRUE(onlyNoLights(scene));
  // Line numbers count from the first line still.
  EXPECT_NE(errorFor(kBom + "v 0 0 0\nv 1 x 0\n").find("scene.obj:2: 'x' is not a number"), std::string::npos);
}

TEST_F(BadInput, NumbersTheLoaderMisreadsAreRefused) {
  EXPECT_NE(errorFor("v 0 0 0\nv 1 0x1p3 -1\nv 0 1 0\nf 1 2 3\n").find("scene.obj:2: '0x1p3' is not a number in 'v'"),
            std::string::npos);
  for (const char* bad : {"0x10", "1e", "1e+", ".", "-", "+.", "1.0abc", "1.5.2", "1,5", "--1", "1e5x", "0e999",
                          "1e-999", "infinity", "-inf", "NaN", "1d5", "0b1"}) {
    SCOPED_TRACE(bad);
    const std::string e = errorFor(std::string(kTriangle) + "vn 0 " + bad + " 1\nf 1 2 3\n");
    EXPECT_NE(e.find("scene.obj:4: "), std::string::npos) << e;
    EXPECT_NE(e.find(bad), std::string::npos) << e;
  }
  EXPECT_NE(errorFor("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 " + std::string(101, '1') + "\nf 1 2 3\n").find("scene.obj:4:"),
            std::string::npos);
  const std::string obj = "mtllib scene.mtl\n" + std::string(kTriangle) + "usemtl a\nf 1 2 3\n";
  EXPECT_NE(errorFor(obj, "newmtl a\nKd 0x1p-1 0 0\n").find("scene.mtl:2: '0x1p-1' is not a number in 'Kd'"),
            std::string::npos);
  EXPECT_NE(errorFor(obj, "newmtl a\nNs 1e\n").find("scene.mtl:2: '1e' is not a number in 'Ns'"), std::string::npos);
  EXPECT_NE(errorFor(obj, "newmtl a\nillum 2abc\n").find("scene.mtl:2: '2abc' is not a number in 'illum'"),
            std::string::npos);
}

// The mechanism: every number the loader reads is one the lint accepted and reads as strtod
// does. Each token of a grammar's worth of forms either is refused or loads as its value.
TEST_F(BadInput, EveryNumberLoadedReadsAsWritten) {
  std::vector<std::string> tokens;
  for (const char* sign : {"", "+", "-"})
    for (const char* whole : {"", "0", "7", "0012"})
      for (const char* dot : {"", "."})
        for (const char* fraction : {"", "5", "25"})
          for (const char* exponent : {"", "e", "E2", "e-3", "e+1", "e400", "e-400", "e00"})
            for (const char* tail : {"", "x", ".", "e"})
              tokens.push_back(std::string(sign) + whole + dot + fraction + exponent + tail);
  for (const char* special :
       {"0x1p3", "0X1P-2", "inf", "nan", "0e500", "-0e999", "1e38", "3.4e38", "1e39", "1e-45", "1e-46"})
    tokens.push_back(special);
  size_t loaded = 0;
  for (const std::string& token : tokens) {
    writeFile(path("n.obj"), "v " + token + " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    Scene scene;
    try {
      scene = loadScene(path("n.obj"));
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("n.obj:1: "), std::string::npos) << e.what();
      continue;
    }
    ++loaded;
    const float expected = std::strtof(token.c_str(), nullptr);
    char* end = nullptr;
    std::strtod(token.c_str(), &end);
    EXPECT_EQ(*end, '\0') << "'" << token << "' loaded but is not a whole number to strtod";
    // In the file's units (a scene far from unit size is scaled by a power of two).
    EXPECT_NEAR(scene.positions[0] / scene.worldScale, expected, 1e-6f * std::fabs(expected)) << "'" << token << "'";
  }
  EXPECT_GT(loaded, 100u);  // the plain forms load
}

// Another format given as the scene is named as such, not reported as "no faces".
TEST_F(BadInput, OtherFormatsAreNotObj) {
  const std::pair<std::string, const char*> files[] = {
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0 0 0\n", "it looks like a PLY file"},
      {"<?xml version=\"1.0\"?>\n<scene version=\"3.0.0\">\n  <shape type=\"obj\"/>\n</scene>\n",
       "it looks like a Mitsuba XML scene"},
      {"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"meshes\": []\n}\n", "it looks like a glTF file"},
      {"solid cube\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n", "it looks like an ASCII STL file"},
      {kBom + "ply\nformat binary_little_endian 1.0\n", "it looks like a PLY file"},
      {"glTF\x02\x00\x00\x00", "it looks like a binary glTF"},
      {"the quick brown fox\njumps over the lazy dog\n", "no line holds an OBJ statement"},
  };
  for (const auto& [text, why] : files) {
    SCOPED_TRACE(why);
    const std::string e = errorFor(text);
    EXPECT_NE(e.find("scene.obj: not an OBJ file (" + std::string(why)), std::string::npos) << e;
  }
  // A binary STL (80-byte header, a triangle count, 50 bytes a triangle), whose header may
  // even start with "solid".
  std::string stl = "solid exported by a CAD tool";
  stl.resize(80, ' ');
  stl += std::string("\x02\x00\x00\x00", 4) + std::string(100, '\0');
  EXPECT_NE(errorFor(stl).find("scene.obj: not an OBJ file (it looks like a binary STL file)"), std::string::npos);
  // A binary blob.
  std::string blob = "\x7f" "ELF";
  for (int i = 0; i < 1000; ++i) blob.push_back(char((i * 7919) % 256));
  EXPECT_NE(errorFor(blob).find("scene.obj: not an OBJ file (binary data"), std::string::npos);
}

// Statements fredholm does not render are said once per kind, and tinyobjloader never reads
// what the lint did not: a face with a trailing comment loads.
TEST_F(BadInput, ObjStatementsReadAsTheLintReadsThem) {
  writeFile(path("scene.obj"), std::string(kTriangle) + "l 1 2\nl 2 3\np 1\nf 1 2 3 # a comment\nxyz 1\n");
  const Scene scene = loadScene(path("scene.obj"));
  EXPECT_EQ(scene.triangleCount(), 1u);
  size_t lines = 0, points = 0, unknown = 0;
  for (const auto& w : scene.warnings) {
    lines += w.find("scene.obj:4: ignored 'l'") != std::string::npos && w.find("(2 statements") != std::string::npos;
    points += w.find("scene.obj:6: ignored 'p'") != std::string::npos;
    unknown += w.find("scene.obj:8: ignored unknown statement 'xyz'") != std::string::npos;
  }
  EXPECT_EQ(lines, 1u);
  EXPECT_EQ(points, 1u);
  EXPECT_EQ(unknown, 1u);
}

// ---- Export ----

// Texture paths are written relative to the exported MTL, so the export can be moved with
// its textures and still load them.
TEST_F(BadInput, ExportWritesTexturePathsRelativeToTheMtl) {
  namespace fs = std::filesystem;
  const std::string root = path("tree");
  fs::create_directories(root + "/source/maps");
  fs::create_directories(root + "/out/deep");
  writeFile(root + "/source/maps/wood.png", "not decoded by the loader");
  writeFile(root + "/source/scene.mtl", "newmtl wood\nKd 0.5\nmap_Kd maps/wood.png\n");
  writeFile(root + "/source/scene.obj",
            "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl wood\nf 1/1 2/2 3/3\n");
  const Scene scene = loadScene(root + "/source/scene.obj");
  ASSERT_EQ(scene.textures.size(), 1u);
  writeObjScene(scene, root + "/out/deep/exported.obj", false);

  std::ifstream in(root + "/out/deep/exported.mtl");
  std::stringstream mtl;
  mtl << in.rdbuf();
  EXPECT_NE(mtl.str().find("\nmap_Kd ../../source/maps/wood.png\n"), std::string::npos) << mtl.str();

  // Moved elsewhere with its textures, the export still finds them.
  fs::rename(root, path("moved"));
  const Scene again = loadScene(path("moved/out/deep/exported.obj"));
  ASSERT_EQ(again.textures.size(), 1u);
  EXPECT_TRUE(fs::equivalent(again.textures[0].path, path("moved/source/maps/wood.png"))) << again.textures[0].path;
  EXPECT_EQ(again.materials[size_t(again.triangleMaterial[0])].kdTexture, 0);
  for (const auto& w : again.warnings) EXPECT_EQ(w.find("texture"), std::string::npos) << w;
}

// Scenes far from unit size are brought near it by a power of two (exact), in-band ones keep
// their units, and an export writes the file's units back.
TEST(SceneLoader, ScenesFarFromUnitSizeAreBroughtNearItExactly) {
  const std::string dir = test::tempDir("units");
  const std::string obj = test::writeFeatureScene(dir);  // 2 units across
  const Scene base = loadScene(obj);
  EXPECT_EQ(base.worldScale, 1.f);
  for (int exponent : {-70, -12, -10, 9, 12, 110}) {
    const Scene scaled = loadScene(test::writeScaledCopy(obj, exponent));
    const int size = exponent + 1;  // the scaled scene is 2^size across
    EXPECT_EQ(scaled.worldScale, size >= -10 && size <= 10 ? 1.f : std::ldexp(1.f, -size)) << exponent;
    ASSERT_EQ(scaled.positions.size(), base.positions.size());
    size_t differing = 0;
    for (size_t i = 0; i < base.positions.size(); ++i)
      differing += scaled.positions[i] != std::ldexp(base.positions[i], exponent) * scaled.worldScale;
    EXPECT_EQ(differing, 0u) << exponent;
    const std::string exported = dir + "/exported" + std::to_string(exponent) + ".obj";
    writeObjScene(scaled, exported, false);
    const Scene again = loadScene(exported);
    EXPECT_EQ(again.worldScale, scaled.worldScale) << exponent;
    EXPECT_EQ(again.positions, scaled.positions) << exponent;
    EXPECT_EQ(again.camera.eye, scaled.camera.eye) << exponent;
  }
}

TEST(SceneLoader, NgonsNegativeIndicesAndCrlf) {
  const std::string dir = test::tempDir("ngon");
  // A pentagon (3 triangles) with relative indices and CRLF line ends.
  writeFile(dir + "/p.obj",
            "v 0 0 0\r\nv 1 0 0\r\nv 1.5 1 0\r\nv 0.5 1.5 0\r\nv -0.5 1 0\r\nf -5 -4 -3 -2 -1\r\n");
  const Scene scene = loadScene(dir + "/p.obj");
  EXPECT_EQ(scene.triangleCount(), 3u);
  for (unsigned i : scene.indices) EXPECT_LT(i, 5u);
}

}  // namespace
}  // namespace fh
