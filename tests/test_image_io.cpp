// Image output: formats by extension, round trips, metadata, and the checks made before
// rendering (unknown extension, unwritable path, no overwrite without --force). Input: every
// file fredholm reads goes through one gate (devices, FIFOs and headers that lie are refused
// in one line naming the file and its role), and compare refuses images that are not finite.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "base/error.h"
#include "image/error_metrics.h"
#include "base/output_plan.h"
#include "image/image_io.h"
#include "test_support.h"

namespace fh {
namespace {

Image gradient(int w, int h) {
  Image img;
  img.width = w;
  img.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.rgb.insert(img.rgb.end(), {x / float(w), y / float(h), 2.5f});
  return img;
}

TEST(ImageIo, ExrKeepsLinearFloatsAndMetadata) {
  const std::string path = test::tempDir("img") + "/a.exr";
  const Image img = gradient(7, 5);
  writeImage(path, img, {{"spp", "16"}, {"method", "mis"}});
  const Image back = readImage(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (size_t i = 0; i < img.rgb.size(); ++i) EXPECT_FLOAT_EQ(back.rgb[i], img.rgb[i]);
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("fredholm:spp"), "16");
  EXPECT_EQ(in->spec().get_string_attribute("fredholm:method"), "mis");
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
}

TEST(ImageIo, PngIsSrgbEncodedAndTopRowFirst) {
  const std::string path = test::tempDir("img") + "/a.png";
  Image img = gradient(4, 4);
  img.rgb[0] = 0.2f;  // top-left red
  writeImage(path, img, {});
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  std::vector<unsigned char> px(4 * 4 * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  EXPECT_EQ(px[0], (unsigned char)std::lround(255.f * linearToSrgb(0.2f)));  // 124, not 51
  EXPECT_EQ(px[2], 255);                                                      // 2.5 clamps
  EXPECT_EQ(px[3 * 4 * 3 + 1], (unsigned char)std::lround(255.f * linearToSrgb(0.75f)));
}

TEST(ImageIo, HdrAndPfmAreFloat) {
  const std::string dir = test::tempDir("img");
  for (const char* ext : {".hdr", ".pfm"}) {
    writeImage(dir + "/a" + ext, gradient(3, 2), {});
    const Image back = readImage(dir + "/a" + ext);
    EXPECT_NEAR(back.rgb[5], 2.5f, 0.05f) << ext;  // above 1: not clamped
  }
}

TEST(ImageIo, ChecksBeforeRendering) {
  const std::string dir = test::tempDir("img");
  // The extension picks the encoding; the place is the output plan's to check (base/output_plan.h).
  const auto planned = [](const std::string& path, bool force) {
    OutputPlan plan(force);
    plan.add(path, "-o");
    plan.reserve();
  };
  EXPECT_EQ(checkImageExtension(dir + "/x.EXR", "-o"), ImageEncoding::LinearFloat);
  EXPECT_EQ(checkImageExtension(dir + "/x.jpg", "-o"), ImageEncoding::Srgb8);
  try {
    checkImageExtension(dir + "/x.tga", "-o");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("-o '" + dir + "/x.tga': unknown image extension '.tga'"),
              std::string::npos);
  }
  EXPECT_THROW(planned(dir + "/no/such/dir/x.png", false), Error);
  test::writeFile(dir + "/old.png", "x");
  EXPECT_THROW(planned(dir + "/old.png", false), Error);
  EXPECT_NO_THROW(planned(dir + "/old.png", true));
  EXPECT_EQ(firstFreeName(dir + "/old.png"), dir + "/old-1.png");
  EXPECT_EQ(firstFreeName(dir + "/new.png"), dir + "/new.png");
}

TEST(ImageIoCli, ExistingOutputIsNotOverwrittenWithoutForce) {
  const std::string dir = test::tempDir("img");
  test::writeFile(dir + "/keep.png", "precious");
  const auto r = test::runFredholm("render -o " + dir + "/keep.png --width 8 --height 8");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("file exists (pass --force"), std::string::npos) << r.output;
  std::ifstream in(dir + "/keep.png");
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
  const auto forced = test::runFredholm("render -o " + dir + "/keep.png --width 8 --height 8 --force");
  EXPECT_EQ(forced.exitCode, 0) << forced.output;
  EXPECT_EQ(readImage(dir + "/keep.png").width, 8);
}

TEST(ImageIoCli, DefaultNameStepsAside) {
  const std::string dir = test::tempDir("img");
  const auto first = test::runFredholm("render --width 8 --height 8", "cd " + dir + " &&");
  ASSERT_EQ(first.exitCode, 0) << first.output;
  const auto second = test::runFredholm("render --width 8 --height 8", "cd " + dir + " &&");
  ASSERT_EQ(second.exitCode, 0) << second.output;
  EXPECT_NE(second.output.find("wrote fredholm-1.png"), std::string::npos) << second.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/fredholm.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/fredholm-1.png"));
}

// A PNG of 66 bytes whose header claims `width` x `height` RGB pixels: the signature, IHDR,
// an IDAT of one deflated byte and IEND, each chunk with its CRC-32 (PNG's, not fredholm's).
std::string lyingPng(uint32_t width, uint32_t height) {
  const auto crc32 = [](const std::string& bytes) {
    uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
  };
  const auto be32 = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16 & 0xff), char(v >> 8 & 0xff), char(v & 0xff)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    return be32(uint32_t(data.size())) + type + data + be32(crc32(type + data));
  };
  const std::string ihdr = be32(width) + be32(height) + std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit RGB
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) +
         chunk("IDAT", std::string("\x78\x9c\x63\x00\x00\x00\x01\x00\x01", 9)) + chunk("IEND", "");
}

// What a CLI run printed is one line: `fredholm: error: ` and `message`, and nothing else.
void expectOneErrorLine(const test::CommandResult& r, const std::string& message, const std::string& what) {
  EXPECT_EQ(r.exitCode, 1) << what << "\n" << r.output;
  EXPECT_EQ(r.output, "fredholm: error: " + message + "\n") << what;
}

// A device (/dev/zero never ends) or a FIFO (opening it waits for a writer) in any role is
// refused at once, in one line naming the role and the file: before the gate, --resume and
// merge read /dev/zero until memory ran out and a FIFO as --camera hung. Each run is killed
// after 60 s, so that a hang fails the test rather than blocking it.
TEST(InputGateCli, DevicesAndFifosAreRefusedInOneLine) {
  const std::string dir = test::tempDir("gate");
  std::filesystem::create_symlink("/dev/zero", dir + "/zero.exr");
  ASSERT_EQ(::mkfifo((dir + "/camera.fifo").c_str(), 0600), 0);
  writeImage(dir + "/ok.exr", gradient(4, 4), {});
  const std::string render = "render --width 8 --height 8 --spp 1 -o " + dir + "/out.png ";
  struct Case {
    std::string args, what, path;
  };
  for (const Case& c : std::vector<Case>{{render + "--camera /dev/zero", "--camera", "/dev/zero"},
                                         {render + "--camera " + dir + "/camera.fifo", "--camera", dir + "/camera.fifo"},
                                         {render + "--resume /dev/zero", "--resume", "/dev/zero"},
                                         {"merge /dev/zero -o " + dir + "/m.exr", "merge", "/dev/zero"},
                                         {"compare /dev/zero " + dir + "/ok.exr", "compare", "/dev/zero"},
                                         {"compare " + dir + "/ok.exr " + dir + "/zero.exr", "compare", dir + "/zero.exr"},
                                         {render + "--env-map " + dir + "/zero.exr", "--env-map", dir + "/zero.exr"}}) {
    const auto r = test::runFredholm(c.args, "timeout -s KILL 60");
    expectOneErrorLine(r, c.what + " '" + c.path + "': is not a regular file (a device, FIFO or socket); give a file",
                       c.args);
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.png"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/m.exr"));
}

// An image whose header claims 100000x100000 pixels in 66 bytes is refused before anything
// is allocated for it, naming the file and the size claimed (it was std::bad_alloc, exit 3).
TEST(InputGate, AnImageHeaderClaimingMoreThanItsFileHoldsIsRefused) {
  const std::string path = test::tempDir("gate") + "/huge.png";
  test::writeFile(path, lyingPng(100000, 100000));
  ASSERT_EQ(std::filesystem::file_size(path), 66u);
  try {
    readImage(path, "compare");
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "compare '" + path + "': its header claims 100000x100000x3 pixels, more than the " +
                                         std::to_string(kMaxImagePixels) + " fredholm reads");
  }
  // Within fredholm's limit but not within 66 bytes.
  test::writeFile(path, lyingPng(8000, 8000));
  try {
    readImage(path, "--env-map");
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--env-map '" + path + "': its header claims 8000x8000x3 pixels, more than its 66 bytes"),
              std::string::npos)
        << e.what();
  }
}

// OpenEXR allocates while it opens a file, before its spec can be checked: an attribute's
// claimed size (a 1.6 GB string in a 900-byte file took 1.7 GB and 1.5 s), and an offset table
// as tall as the data window. Both are claims checked against the file first.
std::string exrAttribute(const std::string& name, const std::string& type, const std::string& value,
                         uint32_t claimed) {
  std::string size(4, '\0');
  for (int i = 0; i < 4; ++i) size[size_t(i)] = char(claimed >> (8 * i) & 0xff);
  return name + '\0' + type + '\0' + size + value;
}

std::string littleEndian(std::vector<int32_t> values) {
  std::string out;
  for (int32_t v : values)
    for (int i = 0; i < 4; ++i) out += char(uint32_t(v) >> (8 * i) & 0xff);
  return out;
}

TEST(InputGate, AnExrHeaderClaimingMoreThanItsFileHoldsIsRefusedBeforeOpenExrOpensIt) {
  const std::string path = test::tempDir("gate") + "/lying.exr";
  const std::string magic("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  const std::string channel = std::string("R") + '\0' + littleEndian({2, 0, 1, 1});  // float, x/y sampling 1
  const std::string channels = exrAttribute("channels", "chlist", channel + "G" + channel.substr(1) + "B" +
                                                                      channel.substr(1) + '\0', 55);
  test::writeFile(path, magic + exrAttribute("software", "string", "fredholm", 1610612740u) + std::string(64, 'x'));
  try {
    readImage(path, "compare");
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "compare '" + path + "': its EXR attribute 'software' claims 1610612740 bytes, more than the file holds");
  }
  test::writeFile(path, magic + channels + exrAttribute("compression", "compression", std::string(1, '\0'), 1) +
                            exrAttribute("dataWindow", "box2i", littleEndian({0, 0, 99999, 99999}), 16) + '\0' +
                            std::string(64, '\0'));
  try {
    readImage(path, "texture");
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "texture '" + path + "': its header claims 100000x100000x3 pixels, more than the " +
                                         std::to_string(kMaxImagePixels) + " fredholm reads");
  }
  // OpenEXR reads a channel list up to its empty name, whatever its size says: one 3 bytes
  // shorter than its channels (found by fuzzing) had OpenEXR read a later string's 1.6 GB claim
  // from where this check saw the end of the header.
  test::writeFile(path, magic + exrAttribute("channels", "chlist", channels.substr(channels.size() - 55), 52) +
                            exrAttribute("spp", "string", "1", 1610612740u) + std::string(64, 'x'));
  try {
    readImage(path, "compare");
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "compare '" + path +
                                         "': its EXR attribute 'channels' of type 'chlist' does not fill the 52 "
                                         "bytes it claims");
  }
  // A vector of strings allocates each string's claim inside the value; a box its 16 bytes.
  for (const std::string& lie : {exrAttribute("names", "stringvector", littleEndian({1610612740}) + "ab", 6),
                                 exrAttribute("dataWindow", "box2i", littleEndian({0, 0, 3}), 12)}) {
    test::writeFile(path, magic + lie + std::string(64, 'x'));
    EXPECT_THROW(readImage(path, "compare"), Error);
  }
  // An EXR fredholm wrote passes.
  writeImage(path, gradient(5, 3), {{"spp", "4"}});
  EXPECT_EQ(readImage(path, "compare").width, 5);
}

// The same PNG as a texture: a warning naming the material, the file and the size claimed,
// and the render goes on with a grey texel, as for any texture that cannot be decoded.
TEST(InputGateCli, ATextureWhoseHeaderLiesIsAWarningNamingItsClaim) {
  const std::string dir = test::tempDir("gate");
  test::writeFile(dir + "/t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                  "usemtl painted\nf 1/1 2/2 3/3\n");
  test::writeFile(dir + "/t.mtl", "newmtl painted\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd huge.png\n");
  test::writeFile(dir + "/huge.png", lyingPng(100000, 100000));
  const auto r = test::runFredholm("render " + dir + "/t.obj --width 8 --height 8 --spp 1 --eye 0.3,0.3,2 "
                                   "--target 0.3,0.3,0 -o " + dir + "/t.pfm",
                                   "timeout -s KILL 120");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("fredholm: warning: material 'painted': texture '" + dir +
                          "/huge.png': its header claims 100000x100000x3 pixels, more than the " +
                          std::to_string(kMaxImagePixels) + " fredholm reads; using a grey texel\n"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("bad_alloc"), std::string::npos) << r.output;
  const auto compared = test::runFredholm("compare " + dir + "/huge.png " + dir + "/t.pfm", "timeout -s KILL 60");
  expectOneErrorLine(compared,
                     "compare '" + dir + "/huge.png': its header claims 100000x100000x3 pixels, more than the " +
                         std::to_string(kMaxImagePixels) + " fredholm reads",
                     "compare");
}

// compare on an image with a NaN or infinite pixel names the file and the first such pixel
// (it printed null metrics and exit 0).
TEST(CompareCli, ANonFiniteImageIsRefusedNamingItsFirstBadPixel) {
  const std::string dir = test::tempDir("gate");
  Image good = gradient(4, 3), nan = good, inf = good;
  nan.rgb[3 * (1 * 4 + 2) + 1] = NAN;       // (2, 1), green
  nan.rgb[3 * (2 * 4 + 3)] = INFINITY;      // (3, 2): later
  inf.rgb[3 * (0 * 4 + 3) + 2] = -INFINITY;  // (3, 0), blue
  writeImage(dir + "/good.exr", good, {});
  writeImage(dir + "/nan.exr", nan, {});
  writeImage(dir + "/inf.exr", inf, {});
  const auto a = test::runFredholm("compare " + dir + "/nan.exr " + dir + "/good.exr");
  EXPECT_EQ(a.exitCode, 1) << a.output;
  EXPECT_NE(a.output.find("fredholm: error: compare '" + dir + "/nan.exr': pixel (2, 1) is not finite ("),
            std::string::npos)
      << a.output;
  const auto b = test::runFredholm("compare " + dir + "/good.exr " + dir + "/inf.exr");
  EXPECT_EQ(b.exitCode, 1) << b.output;
  EXPECT_NE(b.output.find("fredholm: error: compare '" + dir + "/inf.exr': pixel (3, 0) is not finite ("),
            std::string::npos)
      << b.output;
  for (const auto* r : {&a, &b}) {
    EXPECT_EQ(r->output.find("null"), std::string::npos) << r->output;
    EXPECT_EQ(std::count(r->output.begin(), r->output.end(), '\n'), 1) << r->output;
  }
  EXPECT_EQ(test::runFredholm("compare " + dir + "/good.exr " + dir + "/good.exr").exitCode, 0);
}

}  // namespace
}  // namespace fh

namespace fh {
namespace {

TEST(ErrorMetrics, KnownValues) {
  Image ref, img;
  ref.width = img.width = 2;
  ref.height = img.height = 1;
  ref.rgb = {1.f, 1.f, 1.f, 0.f, 0.f, 0.f};
  img.rgb = {1.5f, 1.f, 1.f, 0.1f, 0.f, 0.f};
  const ImageError e = imageError(img, ref);
  // relMSE: (0.25 / 1.01 + 0.01 / 0.01) / 6; RMSE: sqrt(0.26 / 6); MAE: 0.6 / 6.
  EXPECT_NEAR(e.relMse, (0.25 / 1.01 + 1.0) / 6.0, 1e-6);
  EXPECT_NEAR(e.rmse, std::sqrt(0.26 / 6.0), 1e-6);
  EXPECT_NEAR(e.mae, 0.1, 1e-6);
  EXPECT_EQ(imageError(ref, ref).relMse, 0.0);
  Image small = ref;
  small.width = 1;
  EXPECT_THROW(imageError(small, ref), Error);
  EXPECT_NEAR(e.meanImage[0], 0.8, 1e-6);
  EXPECT_NEAR(e.meanReference[0], 0.5, 1e-6);
}

TEST(ErrorMetrics, RequireFiniteNamesTheFirstBadPixel) {
  Image img;
  img.width = 3;
  img.height = 2;
  img.rgb.assign(18, 0.5f);
  EXPECT_NO_THROW(requireFinite(img, "x"));
  img.rgb[3 * 5 + 2] = INFINITY;
  img.rgb[3 * 4] = NAN;
  try {
    requireFinite(img, "compare 'a.exr'");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("compare 'a.exr': pixel (1, 1) is not finite (nan 0.5 0.5)", 0), 0u)
        << e.what();
  }
}

TEST(ErrorMetrics, BlockAverage) {
  Image img;
  img.width = 4;
  img.height = 2;
  for (int i = 0; i < 8; ++i) img.rgb.insert(img.rgb.end(), {float(i), 1.f, 0.f});
  const Image b = blockAverage(img, 2);
  ASSERT_EQ(b.width, 2);
  ASSERT_EQ(b.height, 1);
  EXPECT_EQ(b.rgb, (std::vector<float>{(0 + 1 + 4 + 5) / 4.f, 1.f, 0.f, (2 + 3 + 6 + 7) / 4.f, 1.f, 0.f}));
  EXPECT_EQ(blockAverage(img, 1).rgb, img.rgb);
  EXPECT_THROW(blockAverage(img, 3), Error);
  EXPECT_THROW(blockAverage(img, 0), Error);
}

}  // namespace
}  // namespace fh
