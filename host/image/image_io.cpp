// OpenImageIO output and the checks made before any rendering starts. A build without
// OpenImageIO (the self-contained GPU bundle, bench/gpu/) reads and writes PFM only.
#include "image/image_io.h"

#ifdef FREDHOLM_HAVE_OIIO
#include <OpenImageIO/imageio.h>
#endif

#include <algorithm>
#include <cstdint>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/input_file.h"

namespace fh {
namespace {

namespace fs = std::filesystem;

// Debian 12's OpenImageIO (2.4) reads PFM but has no PFM writer, so fredholm writes it:
// "PF", width height, a negative scale for little-endian, then rows bottom to top.
void writePfm(const std::string& path, const Image& image) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error("cannot create the file");
  out << "PF\n" << image.width << " " << image.height << "\n-1.0\n";
  static_assert(sizeof(float) == 4, "PFM stores 32-bit floats");
  for (int y = image.height - 1; y >= 0; --y)
    out.write(reinterpret_cast<const char*>(&image.rgb[size_t(y) * size_t(image.width) * 3]),
              std::streamsize(size_t(image.width) * 3 * sizeof(float)));
  out.close();
  if (!out) throw Error("the write failed (disk full?)");
}

#ifndef FREDHOLM_HAVE_OIIO
Image readPfm(const std::string& path, const std::string& what) {
  const std::string named = what + " '" + path + "': ";
  checkInputFile(path, what);
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  Image image;
  double scale = 0.0;
  if (!(in >> magic >> image.width >> image.height >> scale) || magic != "PF" || image.width <= 0 ||
      image.height <= 0 || scale >= 0.0 || image.width > (1 << 16) || image.height > (1 << 16))
    throw Error(named + "not a little-endian RGB PFM file");
  in.get();  // the single whitespace byte before the pixels
  // The pixels must be in the file before they are allocated (a header can claim 4G pixels).
  const auto start = in.tellg();
  in.seekg(0, std::ios::end);
  const auto bytes = static_cast<long long>(in.tellg() - start);
  in.seekg(start);
  if (bytes < static_cast<long long>(image.width) * image.height * 12) throw Error(named + "the file ends early");
  image.rgb.resize(size_t(image.width) * size_t(image.height) * 3);
  for (int y = image.height - 1; y >= 0; --y)
    in.read(reinterpret_cast<char*>(&image.rgb[size_t(y) * size_t(image.width) * 3]),
            std::streamsize(size_t(image.width) * 3 * sizeof(float)));
  if (!in) throw Error(named + "the file ends early");
  return image;
}
#endif

}  // namespace

std::string extensionOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

float linearToSrgb(float x) {
  x = std::clamp(x, 0.f, 1.f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.f / 2.4f) - 0.055f;
}

float srgbToLinear(float x) { return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f); }

ImageEncoding checkImageExtension(const std::string& path, const std::string& flag) {
  const std::string ext = extensionOf(path);
  ImageEncoding encoding;
#ifndef FREDHOLM_HAVE_OIIO
  if (ext != ".pfm")
    throw Error(flag + " '" + path + "': this build has no OpenImageIO and writes .pfm only");
#endif
  if (ext == ".exr" || ext == ".hdr" || ext == ".pfm") encoding = ImageEncoding::LinearFloat;
  else if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") encoding = ImageEncoding::Srgb8;
  else
    throw Error(flag + " '" + path + "': unknown image extension '" + ext +
                "' (use .exr, .hdr, .pfm, .png or .jpg)");
  return encoding;
}

std::string firstFreeName(const std::string& path) {
  std::error_code ec;
  for (int i = 0;; ++i) {
    const std::string candidate = numberedName(path, i);
    if (!fs::exists(candidate, ec)) return candidate;
  }
}

namespace {

// The image's R, G, B then every layer's channels, per pixel.
std::vector<float> interleaveLayers(const Image& image, size_t channels) {
  if (image.layers.empty()) return image.rgb;
  const size_t pixels = size_t(image.width) * size_t(image.height);
  std::vector<float> out;
  out.reserve(pixels * channels);
  for (size_t p = 0; p < pixels; ++p) {
    out.insert(out.end(), image.rgb.begin() + long(3 * p), image.rgb.begin() + long(3 * p + 3));
    for (const ImageLayer& layer : image.layers) {
      const size_t n = layer.channels.size();
      out.insert(out.end(), layer.values.begin() + long(n * p), layer.values.begin() + long(n * p + n));
    }
  }
  return out;
}

// Encodes `image` into the file `path` by its extension.
void encodeImage(const std::string& path, const Image& image, ImageEncoding encoding,
                 const std::map<std::string, std::string>& metadata) {
  if (extensionOf(path) == ".pfm") return writePfm(path, image);
#ifdef FREDHOLM_HAVE_OIIO
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw Error(OIIO::geterror());
  const bool isFloat = encoding == ImageEncoding::LinearFloat;
  if (!image.layers.empty() && extensionOf(path) != ".exr") throw Error("image layers need an EXR file");
  std::vector<std::string> channelNames = {"R", "G", "B"};
  for (const ImageLayer& layer : image.layers)
    for (const std::string& c : layer.channels) channelNames.push_back(layer.name + "." + c);
  OIIO::ImageSpec spec(image.width, image.height, int(channelNames.size()),
                       isFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.channelnames = channelNames;
  for (const auto& [key, value] : metadata) spec.attribute("fredholm:" + key, value);
  spec.attribute("Software", "fredholm " FREDHOLM_VERSION);
  if (!isFloat) spec.attribute("oiio:ColorSpace", "sRGB");
  if (!out->open(path, spec)) throw Error(out->geterror());
  bool ok;
  if (isFloat) {
    ok = out->write_image(OIIO::TypeDesc::FLOAT, interleaveLayers(image, channelNames.size()).data());
  } else {
    std::vector<unsigned char> bytes(image.rgb.size());
    for (size_t i = 0; i < bytes.size(); ++i)
      bytes[i] = static_cast<unsigned char>(std::lround(255.f * linearToSrgb(image.rgb[i])));
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  if (!ok || !out->close()) throw Error(out->geterror());
#else
  (void)encoding;
  (void)metadata;
#endif
}

// The file ends in `trailer`.
bool endsWith(const std::string& path, const std::string& trailer) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto size = static_cast<long long>(in.tellg());
  if (!in || size < static_cast<long long>(trailer.size())) return false;
  in.seekg(size - static_cast<long long>(trailer.size()));
  std::string tail(trailer.size(), '\0');
  in.read(&tail[0], std::streamsize(tail.size()));
  return in && tail == trailer;
}

// Some encoders (libpng and libjpeg through OpenImageIO) do not report a failed write. A PNG
// or JPEG must end in its end marker (reading one back would have libpng print to stderr);
// other formats are read back and must decode to the image's size.
void checkComplete(const std::string& path, const Image& image) {
  const std::string ext = extensionOf(path);
  if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") {
    static const std::string iend("\0\0\0\0IEND\xae\x42\x60\x82", 12), eoi("\xff\xd9", 2);
    if (!endsWith(path, ext == ".png" ? iend : eoi)) throw Error("the file written is cut short (disk full?)");
    return;
  }
  Image back;
  try {
    back = readImage(path, "image");
  } catch (const Error&) {
    throw Error("the file written does not decode (disk full?)");
  }
  if (back.width != image.width || back.height != image.height)
    throw Error("the file written does not decode to the image's size");
}

}  // namespace

std::string writeImage(const std::string& path, const Image& image,
                       const std::map<std::string, std::string>& metadata) {
  const ImageEncoding encoding = checkImageExtension(path, "-o");
  return writeAtomically(
      path, "image", [&](const std::string& temp) { encodeImage(temp, image, encoding, metadata); },
      [&](const std::string& temp) { checkComplete(temp, image); });
}

namespace {

// A message of one line: OpenImageIO's errors may run over several.
std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (size_t at; (at = text.find('\n')) != std::string::npos;) text.replace(at, 1, "; ");
  return text.empty() ? "no reason given" : text;
}

#ifdef FREDHOLM_HAVE_OIIO
// A PNG's chunks must fit in its file: libpng allocates what a chunk's header claims before
// reading it (a text chunk claiming 1.7 GB in a 600-byte file, found by fuzzing).
void checkPngChunks(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const long long size = static_cast<long long>(in.tellg());
  in.seekg(8);  // the signature
  for (long long at = 8; at + 12 <= size;) {
    unsigned char header[8];
    if (!in.read(reinterpret_cast<char*>(header), 8)) return;
    const long long length = (static_cast<long long>(header[0]) << 24) | (header[1] << 16) | (header[2] << 8) | header[3];
    if (at + 12 + length > size)
      throw Error(what + " '" + path + "': a PNG chunk claims " + std::to_string(length) +
                  " bytes, more than the file holds");
    if (std::string(reinterpret_cast<char*>(header) + 4, 4) == "IEND") return;
    at += 12 + length;
    in.seekg(at);
  }
}

uint32_t littleEndian32(const unsigned char* b) {
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

// The channels of an EXR channel list: each a name, NUL and 16 bytes, up to an empty name.
// -1 where the list does not end exactly at the end of its value.
long long exrChannelCount(const std::string& value) {
  long long count = 0;
  for (size_t at = 0; at < value.size(); ++count) {
    const size_t end = value.find('\0', at);
    if (end == std::string::npos || end - at > 255) return -1;
    if (end == at) return end + 1 == value.size() ? count : -1;
    at = end + 17;
  }
  return -1;
}

// Whether an attribute's value is laid out as OpenEXR reads its type: the types OpenEXR reads
// by layout must be exactly as long as their size says, and the vectors of strings and the
// preview, which allocate what they read inside the value, must fit in it. Types OpenEXR reads
// by their size alone (string, floatvector, opaque ones) fit by the size check already.
bool exrLayoutFits(const std::string& type, const std::string& value) {
  static const std::map<std::string, size_t> fixedSizes = {
      {"box2i", 16},  {"box2f", 16},      {"v2i", 8},          {"v2f", 8},        {"v2d", 16},    {"v3i", 12},
      {"v3f", 12},    {"v3d", 24},        {"m33f", 36},        {"m33d", 72},      {"m44f", 64},   {"m44d", 128},
      {"int", 4},     {"float", 4},       {"double", 8},       {"rational", 8},   {"timecode", 8}, {"keycode", 28},
      {"envmap", 1},  {"lineOrder", 1},   {"compression", 1},  {"deepImageState", 1}, {"tiledesc", 9},
      {"chromaticities", 32}};
  const auto fixed = fixedSizes.find(type);
  if (fixed != fixedSizes.end()) return value.size() == fixed->second;
  const auto* v = reinterpret_cast<const unsigned char*>(value.data());
  if (type == "chlist") return exrChannelCount(value) >= 0;
  if (type == "preview")
    return value.size() >= 8 &&
           uint64_t(littleEndian32(v)) * littleEndian32(v + 4) * 4 + 8 == uint64_t(value.size());
  if (type == "stringvector") {
    for (size_t at = 0; at < value.size();) {
      if (value.size() - at < 4 || littleEndian32(v + at) > value.size() - at - 4) return false;
      at += 4 + littleEndian32(v + at);
    }
  }
  return true;
}

// An OpenEXR file's headers must fit in it too: OpenEXR allocates what an attribute's size
// claims before reading it (a string attribute claiming 1.6 GB in a 900-byte file, found by
// fuzzing), and an offset table as long as a part's data window is tall, all while opening
// the file, before its spec can be checked. So each attribute must fit in the file, and each
// part's data window and channels are a claim like any header's (checkImageClaim). OpenEXR
// reads most types by their layout, not by the size the attribute gives, so an attribute whose
// layout disagrees with its size is refused too: OpenEXR would read the rest of the header from
// another place than this check does (a channel list 3 bytes short, found by fuzzing, had it
// read a string claiming 1.6 GB that this check never saw). A header cut short is left to
// OpenEXR to report.
void checkExrHeaders(const std::string& path, const std::string& what, uint64_t fileBytes) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8];
  if (!in.read(reinterpret_cast<char*>(head), 8) || littleEndian32(head) != 20000630u) return;
  const bool multiPart = (littleEndian32(head + 4) & 0x1000u) != 0;
  uint64_t at = 8;
  // A name or type: NUL-terminated, at most 255 bytes.
  const auto readName = [&](std::string& text) {
    text.clear();
    for (char c; in.get(c);) {
      ++at;
      if (c == '\0') return true;
      if (text.size() == 255) return false;
      text += c;
    }
    return false;
  };
  for (;;) {
    long long width = 0, height = 0, channels = 0;
    bool window = false, any = false;
    for (std::string name, type;;) {
      if (!readName(name)) return;
      if (name.empty()) break;
      any = true;
      unsigned char size[4];
      if (!readName(type) || !in.read(reinterpret_cast<char*>(size), 4)) return;
      at += 4;
      const uint32_t bytes = littleEndian32(size);
      if (bytes > fileBytes - std::min(at, fileBytes))
        throw Error(what + " '" + path + "': its EXR attribute '" + name + "' claims " + std::to_string(bytes) +
                    " bytes, more than the file holds");
      at += bytes;
      std::string value(bytes, '\0');
      if (bytes > 0 && !in.read(&value[0], std::streamsize(bytes))) return;
      if (!exrLayoutFits(type, value))
        throw Error(what + " '" + path + "': its EXR attribute '" + name + "' of type '" + type + "' does not fill the " +
                    std::to_string(bytes) + " bytes it claims");
      const auto* v = reinterpret_cast<const unsigned char*>(value.data());
      if (name == "dataWindow" && type == "box2i") {
        window = true;
        width = (long long)int32_t(littleEndian32(v + 8)) - (long long)int32_t(littleEndian32(v)) + 1;
        height = (long long)int32_t(littleEndian32(v + 12)) - (long long)int32_t(littleEndian32(v + 4)) + 1;
      } else if (name == "channels" && type == "chlist") {
        channels = exrChannelCount(value);
      }
    }
    if (!any) return;  // the empty header that ends a multi-part file's list
    if (window) checkImageClaim(path, what, width, height, std::max(channels, 1LL), fileBytes, kMaxImagePixels);
    if (!multiPart) return;
  }
}
#endif

}  // namespace

#ifdef FREDHOLM_HAVE_OIIO
std::unique_ptr<OIIO::ImageInput> openImageInput(const std::string& path, const std::string& what) {
  const uint64_t fileBytes = checkInputFile(path, what);
  // By content, not extension: OpenImageIO tries every format on a file its extension's
  // reader refuses.
  unsigned char magic[8] = {};
  std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(magic), 8);
  if (std::memcmp(magic, "\x89PNG\r\n\x1a\n", 8) == 0) checkPngChunks(path, what);
  checkExrHeaders(path, what, fileBytes);
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(what + " '" + path + "': cannot read it as an image (" + oneLine(OIIO::geterror()) + ")");
  const OIIO::ImageSpec& spec = in->spec();
  // No format fredholm reads compresses a pixel below a thousandth of a byte: a header
  // claiming more would have the reader allocate and decode gigabytes of nothing.
  checkImageClaim(path, what, spec.width, spec.height, spec.nchannels, fileBytes, kMaxImagePixels);
  if (spec.depth > 1 || spec.deep)
    throw Error(what + " '" + path + "': a volume or deep image, not a flat one");
  return in;
}
#endif

Image readImage(const std::string& path, const std::string& what) {
#ifndef FREDHOLM_HAVE_OIIO
  return readPfm(path, what);
#else
  const auto in = openImageInput(path, what);
  const OIIO::ImageSpec& spec = in->spec();
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  // The first three channels only: what the image holds beyond R, G, B is never allocated.
  const int used = std::min(spec.nchannels, 3);
  std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(used));
  if (!in->read_image(0, 0, 0, used, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw Error(what + " '" + path + "': cannot decode it (" + oneLine(in->geterror()) + ")");
  const bool srgb = spec.format == OIIO::TypeDesc::UINT8;
  image.rgb.resize(size_t(spec.width) * size_t(spec.height) * 3);
  for (size_t p = 0; p < size_t(spec.width) * size_t(spec.height); ++p)
    for (int c = 0; c < 3; ++c) {
      const float v = pixels[p * size_t(used) + size_t(std::min(c, used - 1))];
      image.rgb[3 * p + size_t(c)] = srgb ? srgbToLinear(v) : v;
    }
  return image;
#endif
}

}  // namespace fh
