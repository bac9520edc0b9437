// Scene loading: every corpus scene loads with the counts its source states (the shared
// corpus' README for the shipped ones, the generator's manifest for the others), and every
// bad input gives a clear error naming the file (and line) or a documented warning.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>

#include "base/error.h"
#include "scene/scene_loader.h"
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
    EXPECT_NE(std::string(e.what()).find("nothing.obj: OBJ file not found"), std::string::npos) << e.what();
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

// Found by fuzzing (issue 17, rows 1-4): inputs the lint passed and the loader read
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

// Devices and FIFOs would block or never end: refused by name (issue 17, row 13).
TEST_F(BadInput, FilesThatAreNotRegularFiles) {
  EXPECT_NE(errorFor("mtllib /dev/zero\n" + std::string(kTriangle) + "f 1 2 3\n").find("/dev/zero: not a regular file"),
            std::string::npos);
  ASSERT_EQ(::mkfifo(path("fifo.obj").c_str(), 0600), 0);
  try {
    loadScene(path("fifo.obj"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fifo.obj: not a regular file"), std::string::npos) << e.what();
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
// (issue 17, row 14: a million unused materials cost 2.2 GB).
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
